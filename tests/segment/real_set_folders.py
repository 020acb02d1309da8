"""Small folders in the layout of LabelMeFacade and of the CMP Facade Database, written
here (no photo of either set may be committed: docs/segment.md, "Real labelled facades").

Names are real names of the committed split lists, so the splits are the lists'.
Each photo is a flat grey-blue image; its labels are the facade pattern below, in the
set's own encoding (LabelMeFacade colours, CMP palette ids).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

# LabelMeFacade: (name, list it is in, its split in the committed list).
LMF_PHOTOS = (
    ("05june05_static_street_boston__p1010736", "test", "test"),
    ("barcelona_static_street__p1010573", "train", "val"),
    ("05june05_static_street_porter__p1010932", "train", "train"),
    ("05june05_static_street_boston__p1010756", "train", "none"),
)
# CMP base facades: (name, split in the committed list).
CMP_PHOTOS = (("cmp_b0001", "test"), ("cmp_b0014", "test"), ("cmp_b0002", "val"),
              ("cmp_b0003", "train"))
CMP_LABEL_NAMES = ("1 background 1\n2 facade 2\n3 window 10\n4 door 5\n5 cornice 11\n"
                   "6 sill 3\n7 balcony 4\n8 blind 6\n9 deco 8\n10 molding 7\n11 pillar 12\n"
                   "12 shop 9\n")
SIZE = (40, 30)  # (H, W)


def cmp_ids() -> np.ndarray:
    """(40, 30) CMP ids: background top rows (1), facade (2), one 10x10 window (3), one
    8x6 door (4), a shop strip (12) and an unlabelled corner (0)."""
    ids = np.full(SIZE, 2, np.uint8)
    ids[:5] = 1  # background (sky)
    ids[10:20, 5:15] = 3  # window, 100 px
    ids[30:38, 20:26] = 4  # door, 48 px
    ids[38:40, :] = 12  # shop, 60 px, not counted
    ids[5:7, 0:2] = 0  # unlabelled, 4 px, not counted
    return ids


def expected_cmp_wwr() -> float:
    """The labels' WWR of :func:`cmp_ids`: window / (wall + window + door) over counted pixels."""
    ids = cmp_ids()
    window, door = int((ids == 3).sum()), int((ids == 4).sum())
    wall = int((ids == 2).sum())
    return window / (wall + window + door)


def write_cmp(root: Path) -> Path:
    """A CMP folder: base/ with the four facades (JPEG photo, palette PNG ids) and
    label_names.txt."""
    base = root / "base"
    base.mkdir(parents=True)
    (base / "label_names.txt").write_text(CMP_LABEL_NAMES)
    for name, _ in CMP_PHOTOS:
        Image.new("RGB", SIZE[::-1], (110, 120, 140)).save(base / f"{name}.jpg")
        label = Image.frombytes("P", SIZE[::-1], cmp_ids().tobytes())
        label.putpalette([(k * 37) % 256 for k in range(3 * 13)])
        label.save(base / f"{name}.png")
    return root


def lmf_colours() -> np.ndarray:
    """(40, 30, 3) LabelMeFacade colours: sky, building with a window and a door, road,
    an unlabelled (various) patch."""
    rgb = np.zeros((*SIZE, 3), np.uint8)
    rgb[:] = (128, 0, 0)  # building
    rgb[:6] = (0, 128, 128)  # sky
    rgb[10:20, 5:15] = (0, 0, 128)  # window
    rgb[28:36, 20:26] = (128, 128, 0)  # door
    rgb[36:] = (128, 64, 0)  # road
    rgb[6:8, 0:3] = (0, 0, 0)  # various
    return rgb


def write_labelmefacade(root: Path) -> Path:
    """A LabelMeFacade folder: images/, labels/, train.txt and test.txt (the last line
    of each without a newline, as in the set)."""
    (root / "images").mkdir(parents=True)
    (root / "labels").mkdir()
    lists: dict[str, list[str]] = {"train": [], "test": []}
    for name, part, _ in LMF_PHOTOS:
        Image.new("RGB", SIZE[::-1], (110, 120, 140)).save(root / "images" / f"{name}.jpg")
        Image.fromarray(lmf_colours()).save(root / "labels" / f"{name}.png")
        lists[part].append(f"images/{name}.jpg")
    for part, lines in lists.items():
        (root / f"{part}.txt").write_text("\n".join(lines))
    return root
