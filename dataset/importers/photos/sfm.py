"""Structure from motion with COLMAP (pycolmap, on the CPU): upright copies of the photos
in, the largest model out, or a clear error when the photos do not overlap. COLMAP's own
log shows its warnings and errors only.

Each camera group (:func:`dataset.importers.photos.photo_folder.camera_groups`) shares one
``SIMPLE_RADIAL`` camera (focal length, principal point, one radial term), started from the
EXIF focal length where there is one (COLMAP's default, 1.2 x the long side, otherwise).
Features: SIFT on each photo scaled down to 1600 px, at most 4096 (:class:`SfmConfig`);
matching: every pair; mapping: incremental, seeded, so a rerun gives the same model. Each
stage's seconds go to a :class:`~dataset.importers.photos.stage_times.StageTimes`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from dataset.importers.photos.photo_folder import Photo, camera_groups
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
    (docs/decisions.md, 2026-11-29)."""

    threads: int = -1
    seed: int = 0
    max_image_px: int = 1600
    max_features: int = 4096

    def __post_init__(self) -> None:
        if self.max_image_px < 100 or self.max_features < 100:
            raise ValueError(f"max_image_px and max_features must be >= 100, got "
                             f"{self.max_image_px} and {self.max_features}")


def reconstruct(photos: Sequence[Photo], upright_dir: Path, work_dir: Path,
                config: SfmConfig = SfmConfig(),
                times: StageTimes | None = None) -> pycolmap.Reconstruction:
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
        models = _models(photos, upright_dir, work_dir, config,
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
    return best


def _models(photos: Sequence[Photo], upright_dir: Path, work_dir: Path,
            config: SfmConfig, times: StageTimes) -> dict[int, pycolmap.Reconstruction]:
    import pycolmap

    database = work_dir / "database.db"
    extraction = pycolmap.FeatureExtractionOptions()
    extraction.num_threads = config.threads
    extraction.max_image_size = config.max_image_px
    extraction.sift.max_num_features = config.max_features
    with times.stage(FEATURES):
        for group in camera_groups(tuple(photos)).values():
            reader = pycolmap.ImageReaderOptions()
            reader.camera_model = "SIMPLE_RADIAL"
            first = group[0]
            if first.focal_px is not None:
                reader.camera_params = f"{first.focal_px},{first.width / 2},{first.height / 2},0"
            pycolmap.extract_features(database, upright_dir,
                                      image_names=[p.name for p in group],
                                      camera_mode=pycolmap.CameraMode.SINGLE,
                                      reader_options=reader, extraction_options=extraction,
                                      device=pycolmap.Device.cpu)
    with times.stage(MATCHING):
        pycolmap.match_exhaustive(database, device=pycolmap.Device.cpu)
    mapping = pycolmap.IncrementalPipelineOptions()
    mapping.num_threads = config.threads
    mapping.random_seed = config.seed
    with times.stage(MAPPING):
        return pycolmap.incremental_mapping(database, upright_dir, work_dir / "sparse", mapping)
