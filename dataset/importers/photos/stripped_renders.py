"""The photos source on renders stripped of their poses: the check that structure from
motion recovers a rendered building's cameras from its images alone (issue 47).

:func:`strip_renders` copies a rendered scene's RGB images of some splits into a folder of
photos (JPEG with the EXIF a camera writes: make, model and the 35 mm equivalent focal
length; no pose, mask or depth); :func:`pose_stripped_renders` runs the photos source on
them with the distance between two of the cameras, as a user pacing it would give it, and
compares the recovered poses with the true ones (:mod:`dataset.importers.photos.pose_error`).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from PIL import ExifTags, Image

from dataset.importers.photos.metric_frame import KnownDistance, ScaleHint
from dataset.importers.photos.photo_folder import FULL_FRAME_WIDTH_MM
from dataset.importers.photos.pose_error import PoseErrors, pose_errors
from dataset.importers.photos.sfm import SfmConfig
from dataset.importers.photos.source import PhotosOptions, read_photos
from dataset.importers.source import write_scenes
from envelope.scene_record import Frame, Scene
from envelope.scenes.scene import read_scene

CAMERA_MAKE = "envelope-bench"
CAMERA_MODEL = "render"
JPEG_QUALITY = 95


@dataclass(frozen=True)
class StrippedRun:
    """What the photos source made of a scene's stripped renders.

    ``views``: photos given; ``posed``: photos it posed; ``known``: the distance given for
    the scale (from the true poses); ``errors``: the posed cameras against the true ones
    (``None`` when structure from motion failed: ``failure`` says why); ``seconds``: wall
    time of the photos source.
    """

    scene: str
    views: int
    posed: int
    known: KnownDistance
    errors: PoseErrors | None
    failure: str
    seconds: float

    @property
    def posed_fraction(self) -> float:
        """Share of the photos that got a pose."""
        return self.posed / self.views


def strip_renders(scene_dir: str | Path, photos_dir: str | Path, splits: Sequence[str],
                  shuffle_seed: int | None = None) -> dict[str, np.ndarray]:
    """Copy the RGB images of ``splits`` of the scene at ``scene_dir`` into ``photos_dir``
    (created) as JPEG photos named ``<frame stem>.jpg`` with camera EXIF; return each photo's
    true (4, 4) world_from_camera pose by photo name. With ``shuffle_seed`` the photos are
    named ``IMG_<n>.jpg`` instead, n a random permutation of 0 .. count - 1 drawn from the
    seed: a user's folder, whose names and order say nothing of where each was taken.

    Raises
    ------
    ValueError
        No frame of those splits in the scene, or ``photos_dir`` exists.
    """
    scene = read_scene(scene_dir)
    frames = _frames(scene, splits)
    photos_dir = Path(photos_dir)
    photos_dir.mkdir(parents=True)
    names = ([_photo_name(f) for f in frames] if shuffle_seed is None else
             [f"IMG_{n:04d}.jpg"
              for n in np.random.default_rng(shuffle_seed).permutation(len(frames))])
    truth = {}
    for frame, name in zip(frames, names):
        k = frame.intrinsics
        exif = Image.Exif()
        exif[ExifTags.Base.Make], exif[ExifTags.Base.Model] = CAMERA_MAKE, CAMERA_MODEL
        focal_35mm = round(k.fx / max(k.width, k.height) * FULL_FRAME_WIDTH_MM)
        exif.get_ifd(ExifTags.IFD.Exif)[ExifTags.Base.FocalLengthIn35mmFilm] = focal_35mm
        with Image.open(scene.path(frame.file_path)) as image:
            image.convert("RGB").save(photos_dir / name, format="JPEG", quality=JPEG_QUALITY,
                                      exif=exif)
        truth[name] = frame.world_from_camera
    return truth


def stripped_poses(scene_dir: str | Path, splits: Sequence[str]) -> dict[str, np.ndarray]:
    """The true poses :func:`strip_renders` returns for these splits, by photo name, without
    copying anything (for photos stripped before).

    Raises
    ------
    ValueError
        No frame of those splits in the scene.
    """
    scene = read_scene(scene_dir)
    return {_photo_name(f): f.world_from_camera for f in _frames(scene, splits)}


def _frames(scene: Scene, splits: Sequence[str]) -> list[Frame]:
    frames = [f for f in scene.frames if f.split in splits]
    if not frames:
        raise ValueError(f"{scene.root} has no frames of splits {list(splits)} (it has "
                         f"{sorted({f.split for f in scene.frames})})")
    return frames


def _photo_name(frame: Frame) -> str:
    return Path(frame.file_path).stem + ".jpg"


def known_pair(truth: dict[str, np.ndarray]) -> KnownDistance:
    """The first photo (by name) and the photo whose camera stands farthest from it, with
    their true distance in metres: a long, well-conditioned baseline a user could pace."""
    names = sorted(truth)
    first = truth[names[0]][:3, 3]
    far = max(names[1:], key=lambda n: float(np.linalg.norm(truth[n][:3, 3] - first)))
    return KnownDistance(names[0], far, float(np.linalg.norm(truth[far][:3, 3] - first)))


def pose_stripped_renders(scene_dir: str | Path, work_dir: str | Path, splits: Sequence[str],
                          *, sfm: SfmConfig | None = None,
                          shuffle_seed: int | None = None) -> StrippedRun:
    """Strip the renders of ``splits`` into ``work_dir / <scene name>`` (``shuffle_seed``:
    under shuffled names, :func:`strip_renders`), pose them with the photos source (``sfm``:
    its structure-from-motion settings, default
    :class:`~dataset.importers.photos.sfm.SfmConfig`; scene written to
    ``work_dir / "posed"``) and compare with the truth."""
    sfm = SfmConfig() if sfm is None else sfm
    scene_dir, work_dir = Path(scene_dir), Path(work_dir)
    photos_dir = work_dir / scene_dir.name
    truth = strip_renders(scene_dir, photos_dir, splits, shuffle_seed)
    known = known_pair(truth)
    options = PhotosOptions(scale=ScaleHint(known_distance=known), sfm=sfm, progress=False)
    start = time.perf_counter()
    try:
        write_scenes(read_photos(photos_dir, options), work_dir / "posed", overwrite=False,
                     progress=False)
    except ValueError as exc:
        return StrippedRun(scene_dir.name, len(truth), 0, known, None, str(exc),
                           time.perf_counter() - start)
    seconds = time.perf_counter() - start
    posed = read_scene(work_dir / "posed" / scene_dir.name).frames
    names = [Path(f.file_path).name for f in posed]
    errors = pose_errors(np.stack([f.world_from_camera for f in posed]),
                         np.stack([truth[n] for n in names]))
    return StrippedRun(scene_dir.name, len(truth), len(posed), known, errors, "", seconds)
