"""Labelled real facade photos: LabelMeFacade and the CMP Facade Database.

One module per set reads a folder the user points at (nothing is downloaded, nothing of
the sets is committed) and maps its labels to the project's classes;
:mod:`segment.real_sets.splits` assigns every photo to ``train``, ``val`` or ``test``
from committed lists. docs/segment.md, "Real labelled facades", says how each set's
classes map.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from segment.real_sets import cmp, labelmefacade
from segment.real_sets.common import IGNORED, RealPhoto, read_labelled

__all__ = ["IGNORED", "RealPhoto", "SET_NAMES", "SOURCES", "read_set", "read_photo_pair"]

_READERS: dict[str, tuple[Callable[[Path], list[RealPhoto]], Callable[[Path], np.ndarray]]] = {
    labelmefacade.SET_NAME: (labelmefacade.labelmefacade_photos,
                             labelmefacade.labelmefacade_labels),
    cmp.SET_NAME: (cmp.cmp_photos, cmp.cmp_labels),
}
SET_NAMES = tuple(_READERS)
"""The sets read here: ``labelmefacade``, ``cmp``."""
SOURCES: dict[str, dict[str, str]] = {labelmefacade.SET_NAME: labelmefacade.SOURCE,
                                      cmp.SET_NAME: cmp.SOURCE}
"""Each set's repository, commit and licence (recorded with weights trained on it)."""


def read_set(set_name: str, root: str | Path) -> list[RealPhoto]:
    """The photos of set ``set_name`` in folder ``root``.

    Raises
    ------
    ValueError
        An unknown set, or a folder that is not a copy of it.
    """
    if set_name not in _READERS:
        raise ValueError(f"unknown real set {set_name!r}; known: {', '.join(SET_NAMES)}")
    return _READERS[set_name][0](Path(root))


def read_photo_pair(photo: RealPhoto) -> tuple[np.ndarray, np.ndarray]:
    """(H, W, 3) uint8 RGB and (H, W) uint8 project class ids (:data:`IGNORED` where not
    counted) of one photo."""
    return read_labelled(photo, _READERS[photo.set_name][1])
