"""LabelMeFacade: 945 street photos labelled per pixel in 9 classes.

Fröhlich, Rodner and Denzler, "A Fast Approach for Pixelwise Labeling of Facade Images",
ICPR 2010; https://github.com/cvjena/labelmefacade (read at commit
``a0dbc272351f9d6914805fbba62d75740308f52f``). Photos from LabelMe; its README: "All
images should only be used for non-commercial and research experiments". Nothing of it
is committed here: the reader takes a clone the user points at.

Layout: ``images/<stem>.jpg``, ``labels/<stem>.png`` (RGB colours, below), ``train.txt``
(100 lines) and ``test.txt`` (845 lines) naming ``images/<stem>.jpg``.

Classes (label colour R:G:B -> project class): building 128:0:0 -> wall (the photos are
taken from the street: roofs, balconies, cornices, sills, shop fronts and signs are all
``building``, so all wall), window 0:0:128 -> window (shop windows included, as
labelled), door 128:128:0 -> door, sky 0:128:128, vegetation 0:128:0, road 128:64:0,
pavement 128:128:128 and car 128:0:128 -> background, various 0:0:0 (unlabelled) ->
not counted.

Group: the LabelMe collection folder (the part of the stem before ``__``: one photo
session of one street, e.g. ``05june05_static_street_boston``); the
``spatial_envelope_256x256_static_8outdoorcategories`` collection, an assembly of many
sources, is grouped by its category and source prefix (``insidecity_art``).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
from PIL import Image

from envelope.classes import SemanticClass
from segment.real_sets.common import IGNORED, RealPhoto

SET_NAME = "labelmefacade"
SOURCE = {
    "repository": "https://github.com/cvjena/labelmefacade",
    "commit": "a0dbc272351f9d6914805fbba62d75740308f52f",
    "licence": "non-commercial research use only (README); not committed here",
}
LISTS = ("train.txt", "test.txt")
"""LabelMeFacade's own image lists."""
COLOURS: dict[tuple[int, int, int], int] = {
    (0, 0, 0): IGNORED,  # various
    (128, 0, 0): SemanticClass.WALL,  # building
    (128, 0, 128): SemanticClass.BACKGROUND,  # car
    (128, 128, 0): SemanticClass.DOOR,  # door
    (128, 128, 128): SemanticClass.BACKGROUND,  # pavement
    (128, 64, 0): SemanticClass.BACKGROUND,  # road
    (0, 128, 128): SemanticClass.BACKGROUND,  # sky
    (0, 128, 0): SemanticClass.BACKGROUND,  # vegetation
    (0, 0, 128): SemanticClass.WINDOW,  # window
}
_MIXED_COLLECTION = "spatial_envelope_256x256_static_8outdoorcategories"


def photo_group(stem: str) -> str:
    """The group of a photo (module doc): its LabelMe collection, or for the mixed
    spatial-envelope collection its category and source prefix."""
    folder, _, rest = stem.partition("__")
    if folder != _MIXED_COLLECTION:
        return folder
    return f"{folder}__{re.sub(r'[0-9]+$', '', rest)}"


def labelmefacade_photos(root: str | Path) -> list[RealPhoto]:
    """Every photo named by ``train.txt`` and ``test.txt`` of a LabelMeFacade clone, in
    list order (``part`` is the list).

    Raises
    ------
    ValueError
        A folder without the lists, or a listed photo without its image or label file.
    """
    root = Path(root)
    photos = []
    for list_name in LISTS:
        listing = root / list_name
        part = Path(list_name).stem
        if not listing.is_file():
            raise ValueError(f"{root} is not a LabelMeFacade folder (no {list_name}); clone "
                             f"{SOURCE['repository']} and give its folder")
        for line in listing.read_text(encoding="utf-8-sig").splitlines():
            if not line.strip():
                continue
            stem = Path(line.strip()).stem
            image, label = root / "images" / f"{stem}.jpg", root / "labels" / f"{stem}.png"
            for needed in (image, label):
                if not needed.is_file():
                    raise ValueError(f"{listing} names {stem} but {needed} is missing")
            photos.append(RealPhoto(SET_NAME, stem, photo_group(stem), part, image, label))
    return photos


def labelmefacade_labels(path: str | Path) -> np.ndarray:
    """A LabelMeFacade label image -> (H, W) uint8 project class ids (:data:`IGNORED` for
    ``various``).

    Raises
    ------
    ValueError
        A colour that is none of the nine classes'.
    """
    with Image.open(path) as img:
        rgb = np.asarray(img.convert("RGB"), dtype=np.uint8)
    return labels_from_colours(rgb, str(path))


def labels_from_colours(rgb: np.ndarray, what: str = "label image") -> np.ndarray:
    """(H, W, 3) uint8 LabelMeFacade colours -> (H, W) uint8 project class ids."""
    codes = (rgb[..., 0].astype(np.int32) << 16) | (rgb[..., 1].astype(np.int32) << 8) \
        | rgb[..., 2].astype(np.int32)
    known = {(r << 16) | (g << 8) | b: cls for (r, g, b), cls in COLOURS.items()}
    uniques, inverse = np.unique(codes, return_inverse=True)
    unknown = [int(u) for u in uniques if int(u) not in known]
    if unknown:
        shown = ", ".join(f"{u >> 16}:{(u >> 8) & 255}:{u & 255}" for u in unknown[:5])
        raise ValueError(f"{what}: colours {shown} are none of LabelMeFacade's nine classes")
    mapped = np.array([known[int(u)] for u in uniques], np.uint8)
    return mapped[inverse.reshape(codes.shape)]
