"""Labelled real photos as training and validation sources of ``python -m segment.train``.

A :class:`RealSource` offers what a render scene offers the training loop
(:class:`segment.training_data.TrainingScene`): a name, ``frames`` (here photos), a
record, and ``rgb_and_labels`` / ``labels`` of a frame. :func:`real_sources` reads the
sets' folders and takes each photo's split from the committed lists
(:mod:`segment.real_sets.splits`): the ``train`` photos of a set are one source (crops
drawn uniformly over its photos), its ``val`` photos another (at most ``val_photos`` of
them, evenly spaced by name, so that a validation takes a bounded time). A ``test`` or
``none`` photo is never returned: nothing trains, or is chosen, on them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from segment.evaluate import evenly_spaced
from segment.real_sets import RealPhoto, read_photo_pair, read_set
from segment.real_sets.common import PHOTO_TRAIN, PHOTO_VAL
from segment.real_sets.splits import committed_splits, split_of


@dataclass(frozen=True)
class RealSource:
    """The photos of one set and split, for training (``split == "train"``) or validation."""

    set_name: str
    split: str
    frames: tuple[RealPhoto, ...]
    record: dict[str, Any]

    @property
    def name(self) -> str:
        return f"{self.set_name}/{self.split}"

    def rgb_and_labels(self, photo: RealPhoto) -> tuple[np.ndarray, np.ndarray]:
        """(H, W, 3) uint8 RGB and (H, W) uint8 class ids (255 where not counted)."""
        return read_photo_pair(photo)

    def labels(self, photo: RealPhoto) -> np.ndarray:
        """(H, W) uint8 class ids of one photo (255 where not counted)."""
        return read_photo_pair(photo)[1]


def real_sources(roots: Mapping[str, Path], val_photos: int = 24
                 ) -> tuple[list[RealSource], list[RealSource]]:
    """(train, validation) sources of the sets in ``roots`` (set name -> folder).

    Raises
    ------
    ValueError
        A folder that is not a copy of its set, or a set without any train photo.
    """
    if val_photos < 1:
        raise ValueError(f"val_photos must be >= 1, got {val_photos}")
    train, val = [], []
    for set_name, root in roots.items():
        photos = read_set(set_name, root)
        committed = committed_splits(set_name)
        by_split: dict[str, list[RealPhoto]] = {PHOTO_TRAIN: [], PHOTO_VAL: []}
        for photo in photos:
            split = split_of(photo, committed)
            if split in by_split:
                by_split[split].append(photo)
        if not by_split[PHOTO_TRAIN]:
            raise ValueError(f"{root}: no photo of {set_name} is in its train split "
                             f"(segment/real_sets/splits/{set_name}.csv)")
        picks = {PHOTO_TRAIN: tuple(by_split[PHOTO_TRAIN]),
                 PHOTO_VAL: evenly_spaced(sorted(by_split[PHOTO_VAL], key=lambda p: p.name),
                                      val_photos)}
        for split, chosen in picks.items():
            if not chosen:
                continue
            record = {"set": set_name, "split": split, "folder": str(root),
                      "photos": len(chosen), "names": [p.name for p in chosen]}
            (train if split == PHOTO_TRAIN else val).append(
                RealSource(set_name, split, chosen, record))
    return train, val
