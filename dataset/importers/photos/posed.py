"""Posed photos: what every way in (structure from motion, an existing COLMAP model, a
nerfstudio ``transforms.json``) gives before the metric frame and the writing, and the
undistortion that turns each into a pinhole image.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from dataset.importers.photos.conventions import world_from_camera_gl
from envelope.camera import Intrinsics
from envelope.photo_io import read_photo_rgb

if TYPE_CHECKING:
    import pycolmap

PINHOLE_MODELS = ("SIMPLE_PINHOLE", "PINHOLE")


@dataclass(frozen=True)
class PosedPhoto:
    """One photo with its camera. ``name``: its file name in the scene's ``images/``;
    ``path``: its pixels, read upright (EXIF orientation applied) when ``upright``, else as
    stored (what COLMAP and nerfstudio read); ``camera``: a COLMAP camera (any model, with
    its distortion); ``world_from_camera``: (4, 4) OpenGL camera-to-world pose in the input's
    frame; ``observed_points``: (N, 3) the sparse points the photo observes (its 2D-3D
    correspondences), input frame, ``None`` where the input has no points (nerfstudio)."""

    name: str
    path: Path
    upright: bool
    camera: pycolmap.Camera
    world_from_camera: np.ndarray
    observed_points: np.ndarray | None = None


@dataclass(frozen=True)
class PosedPhotos:
    """The posed photos of one input, its sparse points ((M, 3), input frame; ``None`` where
    the input has none), the photos left without a pose, and a record of where they came
    from."""

    photos: tuple[PosedPhoto, ...]
    points: np.ndarray | None
    unposed: tuple[str, ...]
    record: dict


def from_reconstruction(model: pycolmap.Reconstruction, image_dir: Path,
                        upright: bool) -> tuple[PosedPhoto, ...]:
    """The registered images of a COLMAP model, sorted by name, their pixels in
    ``image_dir`` under their names.

    Raises
    ------
    ValueError
        An image file is missing.
    """
    photos = []
    for image in sorted((model.images[i] for i in model.reg_image_ids()), key=lambda i: i.name):
        path = image_dir / image.name
        if not path.is_file():
            raise ValueError(f"{path}: the model's image {image.name!r} is not there")
        photos.append(PosedPhoto(Path(image.name).name, path, upright,
                                 model.cameras[image.camera_id],
                                 world_from_camera_gl(image.cam_from_world().matrix()),
                                 observed_points(model, image)))
    return tuple(photos)


def observed_points(model: pycolmap.Reconstruction, image: pycolmap.Image) -> np.ndarray:
    """(N, 3) float64 the model's 3D points ``image`` observes (one per 2D-3D
    correspondence)."""
    xyz = [model.points3D[p.point3D_id].xyz for p in image.get_observation_points2D()]
    return np.asarray(xyz, dtype=np.float64).reshape(-1, 3)


def sparse_points(model: pycolmap.Reconstruction) -> np.ndarray:
    """(M, 3) float64 the model's 3D points."""
    xyz = [p.xyz for p in model.points3D.values()]
    return np.asarray(xyz, dtype=np.float64).reshape(-1, 3)


def undistorted_rgb(photo: PosedPhoto) -> tuple[np.ndarray, Intrinsics]:
    """(H, W, 3) uint8 the photo as a pinhole camera sees it, and that camera's intrinsics
    (COLMAP's undistortion: the image cropped to its valid pixels; a photo without
    distortion as it is).

    Raises
    ------
    ValueError
        An unreadable photo, or one of another size than its camera.
    """
    import pycolmap  # imported here: half a second, for this source alone

    rgb = read_photo_rgb(photo.path, upright=photo.upright)
    cam = photo.camera
    if rgb.shape[:2] != (cam.height, cam.width):
        raise ValueError(f"{photo.path} is {rgb.shape[1]}x{rgb.shape[0]} px, its camera "
                         f"{cam.width}x{cam.height}")
    extra = np.asarray(cam.params)[list(cam.extra_params_idxs())]
    if cam.model_name not in PINHOLE_MODELS and np.any(extra != 0):
        bitmap, cam = pycolmap.undistort_image(pycolmap.UndistortCameraOptions(),
                                               pycolmap.Bitmap.from_array(rgb), cam)
        rgb = bitmap.to_array()
    return rgb, Intrinsics(float(cam.focal_length_x), float(cam.focal_length_y),
                           float(cam.principal_point_x), float(cam.principal_point_y),
                           int(cam.width), int(cam.height))
