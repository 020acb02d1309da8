"""Structure from motion with COLMAP (pycolmap, on the CPU): upright copies of the photos
in, the largest model out, or a clear error when the photos do not overlap. COLMAP's own
log shows its warnings and errors only.

Each camera group (:func:`dataset.importers.photos.photo_folder.camera_groups`) shares one
``SIMPLE_RADIAL`` camera (focal length, principal point, one radial term), started from the
EXIF focal length where there is one (COLMAP's default, 1.2 x the long side, otherwise).
Features: SIFT on each photo scaled down to 1600 px, at most 4096 (:class:`SfmConfig`);
matching: the pairs preemptive matching keeps
(:mod:`dataset.importers.photos.preemptive_pairs`), or every pair; mapping: incremental,
seeded, so a rerun gives the same model. Each stage's seconds go to a
:class:`~dataset.importers.photos.stage_times.StageTimes`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from dataset.importers.photos.photo_folder import Photo, camera_groups
from dataset.importers.photos.preemptive_pairs import (
    ExhaustiveMatching,
    PreemptiveMatching,
    keypoint_scales_px,
    largest_scale_descriptors,
    matches_every_pair,
    preliminary_match_counts,
    selected_pairs,
)
from dataset.importers.photos.stage_times import FEATURES, MAPPING, MATCHING, StageTimes

if TYPE_CHECKING:
    import pycolmap

MIN_REGISTERED_FRACTION = 0.5
"""The largest model must hold at least this share of the photos; fewer means the photos
do not overlap enough to be one building's (the rest are listed and dropped)."""


@dataclass(frozen=True)
class SfmConfig:
    """``threads``: CPU threads (-1: all); ``seed``: the mapper's random seed;
    ``max_image_px``: SIFT sees each photo scaled down to this long side (larger photos
    only); ``max_features``: the most SIFT features kept per photo (COLMAP's
    ``max_num_features``; a feature may have two orientations, so up to about twice as
    many keypoints). Both are COLMAP's "medium" quality (its defaults, "extreme", are 3200
    and 8192): on 12 MP photos they take less than half the CPU time and lose no pose
    (docs/decisions.md, 2026-11-29). ``matching``: which pairs are matched in full:
    :class:`PreemptiveMatching` (the pairs whose largest features agree; near-linear in the
    photos) or :class:`ExhaustiveMatching` (every pair)."""

    threads: int = -1
    seed: int = 0
    max_image_px: int = 1600
    max_features: int = 4096
    matching: PreemptiveMatching | ExhaustiveMatching = PreemptiveMatching()

    def __post_init__(self) -> None:
        if self.max_image_px < 100 or self.max_features < 100:
            raise ValueError(f"max_image_px and max_features must be >= 100, got "
                             f"{self.max_image_px} and {self.max_features}")


@dataclass(frozen=True)
class Reconstructed:
    """The largest model, and how many pairs of photos were matched in full (of
    ``all_pairs``, n (n - 1) / 2)."""

    model: pycolmap.Reconstruction
    matched_pairs: int
    all_pairs: int


def reconstruct(photos: Sequence[Photo], upright_dir: Path, work_dir: Path,
                config: SfmConfig = SfmConfig(),
                times: StageTimes | None = None) -> Reconstructed:
    """The largest COLMAP model of ``photos``, whose upright copies lie in ``upright_dir``
    under their names; COLMAP's database and models go to ``work_dir``; ``times``, where
    given, gets the seconds of feature extraction, matching and mapping.

    Raises
    ------
    ValueError
        No model, or one holding fewer than :data:`MIN_REGISTERED_FRACTION` of the photos
        (the message says how many were placed and what to photograph).
    """
    import pycolmap  # imported here: half a second, for this source alone

    previous = pycolmap.logging.minloglevel
    pycolmap.logging.minloglevel = int(pycolmap.logging.WARNING)
    try:
        models, matched = _models(photos, upright_dir, work_dir, config,
                                  StageTimes() if times is None else times)
    finally:
        pycolmap.logging.minloglevel = previous
    best = max(models.values(), key=lambda r: r.num_reg_images(), default=None)
    placed = 0 if best is None else best.num_reg_images()
    if placed < max(2, MIN_REGISTERED_FRACTION * len(photos)):
        raise ValueError(
            f"structure from motion placed {placed} of {len(photos)} photos in one model "
            f"({len(models)} models): the photos do not overlap enough. Photograph the building "
            "walking round it, each photo overlapping the last by well over half, each part in "
            "three photos or more, avoiding plain walls and glass filling the frame")
    return Reconstructed(best, matched, len(photos) * (len(photos) - 1) // 2)


def _models(photos: Sequence[Photo], upright_dir: Path, work_dir: Path, config: SfmConfig,
            times: StageTimes) -> tuple[dict[int, pycolmap.Reconstruction], int]:
    """COLMAP's models by index, and the number of pairs matched in full. With preemptive
    matching, photos the largest model leaves out get a second chance: each is matched with
    every other photo and the mapping runs again (:class:`PreemptiveMatching`); a set small
    enough is matched in every pair (:func:`matches_every_pair`)."""
    import pycolmap

    database = work_dir / "database.db"
    with times.stage(FEATURES):
        extract_features(photos, upright_dir, database, config)
    names = sorted(p.name for p in photos)
    preemptive = not matches_every_pair(config.matching, len(photos))
    with times.stage(MATCHING):
        if preemptive:
            pairs = set(preemptive_pairs(database, config.matching))
            _match_pairs(database, work_dir / "pairs.txt", sorted(pairs))
        else:
            pycolmap.match_exhaustive(database, device=pycolmap.Device.cpu)
            pairs = {(a, b) for i, a in enumerate(names) for b in names[i + 1:]}
    with times.stage(MAPPING):
        models = _mapping(database, upright_dir, work_dir / "sparse", config)
    left_out = set(names) - _largest_model_names(models)
    if not left_out or not preemptive:
        return models, len(pairs)
    more = sorted({(min(a, b), max(a, b)) for a in left_out for b in names if a != b} - pairs)
    with times.stage(MATCHING):
        _match_pairs(database, work_dir / "pairs-left-out.txt", more)
    with times.stage(MAPPING):
        again = _mapping(database, upright_dir, work_dir / "sparse-again", config)
    if len(_largest_model_names(again)) > len(set(names) - left_out):
        models = again
    return models, len(pairs) + len(more)


def _match_pairs(database: Path, pairs_path: Path, pairs: list[tuple[str, str]]) -> None:
    """Match and verify ``pairs`` of image names in full (the list goes to ``pairs_path``)."""
    import pycolmap

    pairs_path.write_text("".join(f"{a} {b}\n" for a, b in pairs))
    pycolmap.match_image_pairs(database, pairing_options=pycolmap.ImportedPairingOptions(
        match_list_path=pairs_path), device=pycolmap.Device.cpu)


def _mapping(database: Path, upright_dir: Path, out_dir: Path,
             config: SfmConfig) -> dict[int, pycolmap.Reconstruction]:
    import pycolmap

    mapping = pycolmap.IncrementalPipelineOptions()
    mapping.num_threads = config.threads
    mapping.random_seed = config.seed
    return pycolmap.incremental_mapping(database, upright_dir, out_dir, mapping)


def _largest_model_names(models: dict[int, pycolmap.Reconstruction]) -> set[str]:
    best = max(models.values(), key=lambda r: r.num_reg_images(), default=None)
    return set() if best is None else {best.images[i].name for i in best.reg_image_ids()}


def extract_features(photos: Sequence[Photo], upright_dir: Path, database: Path,
                     config: SfmConfig) -> None:
    """SIFT features of ``photos`` (upright copies in ``upright_dir``) into COLMAP's
    ``database``, one shared camera per camera group."""
    import pycolmap

    extraction = pycolmap.FeatureExtractionOptions()
    extraction.num_threads = config.threads
    extraction.max_image_size = config.max_image_px
    extraction.sift.max_num_features = config.max_features
    for group in camera_groups(tuple(photos)).values():
        reader = pycolmap.ImageReaderOptions()
        reader.camera_model = "SIMPLE_RADIAL"
        first = group[0]
        if first.focal_px is not None:
            reader.camera_params = f"{first.focal_px},{first.width / 2},{first.height / 2},0"
        pycolmap.extract_features(database, upright_dir, image_names=[p.name for p in group],
                                  camera_mode=pycolmap.CameraMode.SINGLE, reader_options=reader,
                                  extraction_options=extraction, device=pycolmap.Device.cpu)


def preliminary_counts(database: Path, top_features: int,
                       max_ratio: float) -> tuple[list[str], np.ndarray]:
    """The image names in COLMAP's ``database`` (features extracted), sorted, and their
    (n, n) preliminary matches on each one's ``top_features`` largest features
    (:func:`~dataset.importers.photos.preemptive_pairs.preliminary_match_counts`)."""
    import pycolmap

    db = pycolmap.Database.open(database)
    try:
        images = sorted(db.read_all_images(), key=lambda im: im.name)
        top = [largest_scale_descriptors(np.asarray(db.read_descriptors(im.image_id).data),
                                         keypoint_scales_px(db.read_keypoints(im.image_id)),
                                         top_features) for im in images]
    finally:
        db.close()
    return [im.name for im in images], preliminary_match_counts(top, max_ratio)


def preemptive_pairs(database: Path, matching: PreemptiveMatching) -> list[tuple[str, str]]:
    """The pairs of image names in COLMAP's ``database`` (features extracted) that
    ``matching`` keeps (:func:`~dataset.importers.photos.preemptive_pairs.selected_pairs`),
    each pair in name order, sorted."""
    names, counts = preliminary_counts(database, matching.top_features, matching.max_ratio)
    return sorted((names[i], names[j]) for i, j in selected_pairs(counts, matching.min_matches,
                                                                  matching.min_partners))
