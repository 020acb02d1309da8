"""The ``photos`` source: ``python -m dataset.generate --photos DIR --out OUT`` writes one
scene ``OUT/<DIR's name>`` from a folder of photos, an existing COLMAP project or a
nerfstudio ``transforms.json`` (docs/importing.md, section 9).

The scene holds ``transforms.json`` (every posed photo a ``train`` frame, OpenGL
camera-to-world poses in metres with z up, pinhole intrinsics) and ``images/`` (the photos
undistorted, upright), ``depth/`` (each photo's depth from the sparse points it observes,
:mod:`dataset.importers.photos.photo_depth`; none from a nerfstudio file), no masks and no
``building.json``: photos carry no truth.
Its ``photos`` record says how the poses, up, scale and origin were found and which photos
got no pose. The scale is checked before anything runs (none given: refused); the scene is
written into a temporary folder renamed when complete, so a failure leaves nothing.
"""

from __future__ import annotations

import os
import shutil
import sys
import tempfile
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, replace
from functools import partial
from pathlib import Path

import numpy as np
from PIL import ExifTags, Image
from tqdm import tqdm

from dataset.importers.photos.city_target import CityTarget, read_city_target
from dataset.importers.photos.existing import (
    colmap_model_folder,
    read_colmap_project,
    read_nerfstudio,
    transforms_file,
)
from dataset.importers.photos.gps import read_gps_fix
from dataset.importers.photos.gps_frame import check_photo_fixes
from dataset.importers.photos.metric_frame import (
    NO_SCALE,
    ScaleHint,
    Similarity,
    metric_similarity,
)
from dataset.importers.photos.photo_depth import with_photo_depths
from dataset.importers.photos.photo_folder import PHOTO_SUFFIXES, Photo, list_photos
from dataset.importers.photos.posed import (
    PosedPhoto,
    PosedPhotos,
    from_reconstruction,
    sparse_points,
    undistorted_rgb,
)
from dataset.importers.photos.preemptive_pairs import ExhaustiveMatching, PreemptiveMatching
from dataset.importers.photos.sfm import SfmConfig, reconstruct
from dataset.importers.photos.stage_times import (
    DEPTH,
    METRIC_FRAME,
    READING,
    WRITING,
    StageTimes,
)
from dataset.importers.source import SceneEntry, Source
from envelope.photo_io import read_photo_rgb
from envelope.protocols import TRAIN_PROTOCOL
from envelope.scene_record import Frame, Scene
from envelope.scenes.scene import write_transforms

JPEG_QUALITY = 95
"""Undistorted JPEG photos are written again as JPEG at this quality (PNG stays PNG)."""
RECORD_KEY = "photos"


@dataclass(frozen=True)
class PhotosOptions:
    """What the photos source reads: the scale the user knows (``None``: refused, with the
    options to give) and the structure-from-motion settings."""

    scale: ScaleHint | None = None
    sfm: SfmConfig = SfmConfig()
    progress: bool = True


def read_photos(path: str | Path, options: PhotosOptions) -> tuple[SceneEntry, ...]:
    """One scene entry for the photos at ``path``, named by the folder; the photos and the
    scale are checked now, structure from motion runs when the scene is written.

    Raises
    ------
    ValueError
        No scale given, or (a folder of photos) as
        :func:`dataset.importers.photos.photo_folder.list_photos`, a known distance naming
        no photo, (``--gps``) too few GPS fixes or fixes too close together, or
        (``--city-model``) a city model that is not readable CityGML or lacks the building
        named (:func:`dataset.importers.photos.city_target.read_city_target`).
    """
    path = Path(path)
    if options.scale is None:
        raise ValueError(NO_SCALE)
    city = None if options.scale.city_model is None else read_city_target(
        options.scale.city_model, options.scale.city_building)
    if colmap_model_folder(path) is not None:
        return (SceneEntry(path.resolve().name, partial(
            _write, partial(_read_posed, read_colmap_project), path, options, city)),)
    if transforms_file(path) is not None:
        folder = path if path.is_dir() else path.parent
        return (SceneEntry(folder.resolve().name, partial(
            _write, partial(_read_posed, read_nerfstudio), path, options, city)),)
    photos = list_photos(path)
    known = options.scale.known_distance
    missing = [] if known is None else [n for n in (known.photo_a, known.photo_b)
                                        if n not in {p.name for p in photos}]
    if missing:
        raise ValueError(f"--known-distance names {', '.join(missing)}, which is not a photo "
                         f"of {path} (give the photos' file names, e.g. {photos[0].name})")
    if options.scale.gps:
        check_photo_fixes([read_gps_fix(p.path) for p in photos])
    return (SceneEntry(path.resolve().name, partial(_write, partial(_structure_from_motion,
                                                                    photos, options.sfm),
                                                    path, options, city)),)


def detect_photos(path: str | Path) -> bool:
    """Whether ``path`` is a COLMAP project, a nerfstudio ``transforms.json`` or a folder
    holding photos (cheap; never raises)."""
    try:
        path = Path(path)
        return (colmap_model_folder(path) is not None or transforms_file(path) is not None
                or (path.is_dir() and any(p.suffix.lower() in PHOTO_SUFFIXES
                                          for p in path.iterdir())))
    except OSError:
        return False


def _read_posed(read: Callable[[Path], PosedPhotos], path: Path,
                times: StageTimes) -> PosedPhotos:
    with times.stage(READING):
        return read(path)


def _structure_from_motion(photos: tuple[Photo, ...], config: SfmConfig,
                           path: Path, times: StageTimes) -> PosedPhotos:
    with tempfile.TemporaryDirectory(prefix="photos-sfm-") as work:
        upright = Path(work) / "upright"
        upright.mkdir()
        with times.stage(READING), ThreadPoolExecutor(_threads(config)) as pool:
            # Threads: decoding a photo leaves Python's lock.
            list(pool.map(partial(_upright_copy, upright), photos))
        built = reconstruct(photos, upright, Path(work), config, times)
        model = built.model
        posed = from_reconstruction(model, upright, upright=True)
        # The upright copies go with the temporary folder: point back at the photos.
        posed = tuple(replace(p, path=path / p.name) for p in posed)
        placed = {p.name for p in posed}
        return PosedPhotos(posed, sparse_points(model),
                           tuple(p.name for p in photos if p.name not in placed),
                           {"input": "photos", "structure_from_motion": "COLMAP (pycolmap) "
                            "incremental mapping, SIFT, CPU",
                            "matching": _matching_label(config.matching),
                            "matched_pairs": built.matched_pairs,
                            "all_pairs": built.all_pairs,
                            "sift_max_image_px": config.max_image_px,
                            "sift_max_features": config.max_features,
                            "mean_reprojection_error_px":
                                round(float(model.compute_mean_reprojection_error()), 4)})


def _upright_copy(upright: Path, photo: Photo) -> None:
    """Decode ``photo`` (a broken file stops the run here, before COLMAP sees it) and put an
    upright copy of it into ``upright`` under its name."""
    rgb = read_photo_rgb(photo.path)
    if _read_alike_by_colmap(photo.path):
        shutil.copyfile(photo.path, upright / photo.name)  # no encoding: faster
    else:
        Image.fromarray(rgb).save(upright / photo.name, format="PNG", compress_level=1)


def _threads(config: SfmConfig) -> int:
    """The threads ``config`` asks for (-1: one per CPU core)."""
    return (os.cpu_count() or 1) if config.threads == -1 else config.threads


def _matching_label(matching: PreemptiveMatching | ExhaustiveMatching) -> str:
    if isinstance(matching, ExhaustiveMatching):
        return "exhaustive (every pair)"
    return (f"preemptive: pairs with >= {matching.min_matches} matches of their "
            f"{matching.top_features} largest features, and each photo's "
            f"{matching.min_partners} best; every pair up to {matching.every_pair_up_to} "
            f"photos")


def _read_alike_by_colmap(path: Path) -> bool:
    """Whether COLMAP reads the file's pixels as :func:`read_photo_rgb` gives them: an 8-bit
    RGB or grey JPEG or PNG stored upright (no EXIF orientation, or the identity)."""
    with Image.open(path) as img:
        return (img.format in ("JPEG", "PNG") and img.mode in ("RGB", "L")
                and img.getexif().get(ExifTags.Base.Orientation, 1) == 1)


def _write(read: Callable[[Path, StageTimes], PosedPhotos], path: Path,
           options: PhotosOptions, city: CityTarget | None, out_dir: Path) -> Scene:
    """Pose the photos of ``path`` with ``read`` (which times its own stages), take them to
    metres and z up (``city``: the city model read for ``--city-model``), and write the
    scene into ``out_dir``."""
    times = StageTimes()
    posed = read(path, times)
    names = [p.name for p in posed.photos]
    if len(set(names)) != len(names):
        raise ValueError(f"{path}: two images share a file name; rename them")
    with times.stage(METRIC_FRAME):
        similarity, frame_record = metric_similarity(
            np.stack([p.world_from_camera for p in posed.photos]), names, posed.points,
            options.scale, tuple(read_gps_fix(p.path) for p in posed.photos)
            if options.scale.gps else None, city)
    (out_dir / "images").mkdir()
    threads = _threads(options.sfm)
    with times.stage(WRITING), ThreadPoolExecutor(threads) as pool:
        # Threads: decoding, undistorting and encoding a photo leave Python's lock.
        frames = list(tqdm(pool.map(partial(_write_photo, out_dir, similarity), posed.photos),
                           total=len(posed.photos), desc="photos", unit="photo",
                           disable=not options.progress))
    record = {**posed.record, **frame_record, "posed": len(frames),
              "unposed": list(posed.unposed), "scale_factor": similarity.scale}
    scene = Scene(out_dir, tuple(frames), extra={RECORD_KEY: record})
    with times.stage(DEPTH):
        scene = with_photo_depths(scene, posed.photos, similarity, RECORD_KEY, threads=threads)
    scene = replace(scene, extra={**scene.extra, RECORD_KEY: {**scene.extra[RECORD_KEY],
                                                              **times.record()}})
    if options.progress:
        print(f"{path.name}: {len(frames)} photos posed; {times.summary()}", file=sys.stderr)
    write_transforms(out_dir, scene)
    return scene


def _write_photo(out_dir: Path, similarity: Similarity, photo: PosedPhoto) -> Frame:
    rgb, intrinsics = undistorted_rgb(photo)
    relative = f"images/{photo.name}"
    jpeg = Path(photo.name).suffix.lower() in (".jpg", ".jpeg")
    Image.fromarray(rgb).save(out_dir / relative, **(
        {"format": "JPEG", "quality": JPEG_QUALITY} if jpeg else {"format": "PNG"}))
    return Frame(relative, similarity.pose(photo.world_from_camera), intrinsics, TRAIN_PROTOCOL)


PHOTOS_SOURCE = Source(
    name="photos", flag="--photos",
    help="a folder of JPEG or PNG photos of one building (poses from structure from motion), "
         "a COLMAP project (sparse/0 and images/) or a nerfstudio transforms.json; needs "
         "--known-distance, --known-height, --gps or --city-model for the scale",
    detect=detect_photos, read=read_photos, options_type=PhotosOptions,
)
