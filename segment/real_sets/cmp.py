"""The CMP Facade Database: 606 rectified facades labelled per pixel in 12 classes.

Tyleček and Šára, "Spatial Pattern Templates for Recognition of Objects with Regular
Structure", GCPR 2013; https://cmp.felk.cvut.cz/~tylecr1/facade/ (``CMP_facade_DB_base``:
378 facades ``cmp_b*``; ``CMP_facade_DB_extended``: 228 facades ``cmp_x*``). The copy
read here is the base set as committed in
https://github.com/Thunderwisking/CMP_facade_Toolf4InstanceSegmentation (commit
``016215164fe18104172c15d829f3cfaa8e0cbc8f``, folder ``base/``): no public GitHub copy
of the extended set was found. Neither the database's README nor that copy states a
licence, so nothing of it is committed here: the reader takes a folder the user points at.

Layout: ``<root>/base/cmp_b*.{jpg,png}`` and ``<root>/extended/cmp_x*.{jpg,png}`` as
the two zips unpack (either may be absent), or the files directly in ``<root>``; the
PNG holds the label id of each pixel (a palette image). ``label_names.txt``, where the
folder has one, must name the ids as below.

Classes (CMP id name -> project class): 1 background -> background (sky, neighbours,
ground: what is not the facade); 2 facade, 5 cornice, 6 sill, 9 deco, 10 molding,
11 pillar -> wall (opaque facade surface and its relief); 3 window -> window; 4 door ->
door; 8 blind -> wall (shutters, mostly open beside the window on the wall; a closed one
over its window then counts as wall, so the labels' WWR is low on such facades);
7 balcony -> other (slabs and railings in front of the facade); 12 shop -> not counted
(a ground-floor shop front labelled as one region of glazing, signs and entrances: no
project class fits it); 0 (unlabelled) -> not counted.

Group: the facade itself (the database gives no building ids; each facade is one
building's).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

from envelope.classes import SemanticClass
from segment.real_sets.common import IGNORED, RealPhoto, lookup_labels

SET_NAME = "cmp"
SOURCE = {
    "repository": "https://github.com/Thunderwisking/CMP_facade_Toolf4InstanceSegmentation",
    "commit": "016215164fe18104172c15d829f3cfaa8e0cbc8f",
    "licence": "none stated (database README and copy); not committed here",
}
CMP_NAMES = ("unknown", "background", "facade", "window", "door", "cornice", "sill",
             "balcony", "blind", "deco", "molding", "pillar", "shop")
"""CMP label id -> name (``label_names.txt``; id 0 is unlabelled)."""
CMP_CLASSES: dict[int, int] = {
    0: IGNORED,
    1: SemanticClass.BACKGROUND,
    2: SemanticClass.WALL,
    3: SemanticClass.WINDOW,
    4: SemanticClass.DOOR,
    5: SemanticClass.WALL,  # cornice
    6: SemanticClass.WALL,  # sill
    7: SemanticClass.OTHER,  # balcony
    8: SemanticClass.WALL,  # blind (shutters)
    9: SemanticClass.WALL,  # deco
    10: SemanticClass.WALL,  # molding
    11: SemanticClass.WALL,  # pillar
    12: IGNORED,  # shop
}
PARTS = {"cmp_b": "base", "cmp_x": "extended"}
"""File-name prefix -> the database's subset."""


def cmp_photos(root: str | Path) -> list[RealPhoto]:
    """Every labelled facade (a ``cmp_*.jpg`` with its ``.png``) of a CMP folder, sorted by
    name (``part`` is ``base`` or ``extended``).

    Raises
    ------
    ValueError
        A folder without any facade, a facade image without its label file, or a
        ``label_names.txt`` that names the ids otherwise.
    """
    root = Path(root)
    folders = [f for f in (root / "base", root / "extended", root) if f.is_dir()]
    for folder in folders:
        check_label_names(folder / "label_names.txt")
    photos = []
    for folder in folders:
        for image in sorted(folder.glob("cmp_*.jpg")):
            part = PARTS.get(image.stem[:5])
            if part is None:
                raise ValueError(f"{image}: a CMP facade is named cmp_b* or cmp_x*")
            label = image.with_suffix(".png")
            if not label.is_file():
                raise ValueError(f"{image} has no label image {label.name}")
            photos.append(RealPhoto(SET_NAME, image.stem, image.stem, part, image, label))
    if not photos:
        raise ValueError(f"{root} holds no CMP facade (cmp_*.jpg with its .png, in base/, "
                         f"extended/ or the folder itself)")
    return sorted(photos, key=lambda p: p.name)


def check_label_names(path: Path) -> None:
    """Refuse a ``label_names.txt`` (lines ``id name z_order``) whose ids name other classes
    than :data:`CMP_NAMES`; a missing file is accepted."""
    if not path.is_file():
        return
    for line in path.read_text().splitlines():
        parts = line.split()
        if len(parts) >= 2 and parts[0].isdigit():
            k = int(parts[0])
            if k >= len(CMP_NAMES) or CMP_NAMES[k] != parts[1].lower():
                raise ValueError(f"{path}: id {k} is {parts[1]!r} here, but the CMP Facade "
                                 f"Database's is {CMP_NAMES[k] if k < len(CMP_NAMES) else None!r}")


def cmp_labels(path: str | Path) -> np.ndarray:
    """A CMP label image (palette or grey PNG of ids 0-12) -> (H, W) uint8 project class ids.

    Raises
    ------
    ValueError
        A colour image (the ids are lost), or an id above 12.
    """
    with Image.open(path) as img:
        if img.mode not in ("P", "L"):
            raise ValueError(f"{path}: a CMP label image holds one id per pixel (palette or "
                             f"grey), got mode {img.mode}")
        ids = np.asarray(img, dtype=np.uint8)
    return lookup_labels(ids, CMP_CLASSES, str(path))
