"""What every labelled real-photo set gives: photos with a label image, read as the
project's classes.

A set's reader (:mod:`segment.real_sets.labelmefacade`, :mod:`segment.real_sets.cmp`)
lists :class:`RealPhoto` entries from a folder the user points at and maps the set's
label colours or ids to the project's classes (``envelope.classes``: 0 background,
1 wall, 2 window, 3 roof, 4 door, 5 other); pixels no project class fits are
:data:`IGNORED` and count nowhere (not in an IoU, a WWR or a training loss).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from envelope.photo_io import read_photo_rgb

PHOTO_TRAIN, PHOTO_VAL, PHOTO_TEST = "train", "val", "test"
PHOTO_SPLITS = (PHOTO_TRAIN, PHOTO_VAL, PHOTO_TEST)
"""The splits of the real photo sets (:mod:`segment.real_sets.splits`), spelled once; not
the scene frames' splits (:mod:`envelope.protocols`)."""
IGNORED = 255
"""Label of a pixel that is not counted (unlabelled, or a class that fits no project class)."""


@dataclass(frozen=True)
class RealPhoto:
    """One labelled photo of a real set.

    ``name`` (the image file's stem) is the key of the committed split lists; ``group``
    names the photos that may show the same building (a split never divides a group);
    ``part`` is the set's own subset (LabelMeFacade's ``train``/``test`` list, CMP's
    ``base``/``extended``).
    """

    set_name: str
    name: str
    group: str
    part: str
    image_path: Path
    label_path: Path


def read_labelled(photo: RealPhoto,
                  read_labels: Callable[[Path], np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """The photo's (H, W, 3) uint8 RGB and its (H, W) uint8 project class ids
    (:data:`IGNORED` where not counted), read by ``read_labels``.

    Raises
    ------
    ValueError
        An unreadable image or label file, or a label image of another size than the photo.
    """
    rgb = read_photo_rgb(photo.image_path)
    labels = read_labels(photo.label_path)
    if labels.shape != rgb.shape[:2]:
        raise ValueError(f"{photo.label_path} is {labels.shape[1]}x{labels.shape[0]} px but "
                         f"its photo {photo.image_path.name} is {rgb.shape[1]}x{rgb.shape[0]}")
    return rgb, labels


def lookup_labels(values: np.ndarray, table: dict[int, int], what: str) -> np.ndarray:
    """(H, W) integer label ids -> (H, W) uint8 project ids through ``table``.

    Raises
    ------
    ValueError
        An id the table does not hold (a label image of another set or version).
    """
    lut = np.full(max(max(table), int(values.max(initial=0))) + 1, -1, np.int16)
    for source, target in table.items():
        lut[source] = target
    out = lut[values]
    if (out < 0).any():
        unknown = sorted(set(np.unique(values[out < 0]).tolist()))
        raise ValueError(f"{what}: label ids {unknown[:8]} are none of this set's "
                         f"({sorted(table)}); is it a label image of this set?")
    return out.astype(np.uint8)
