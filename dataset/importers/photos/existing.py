"""Inputs already posed, taken as they are: a COLMAP model (a project folder with
``sparse/0/`` (or ``sparse/``) holding ``cameras``, ``images`` and ``points3D`` (``.bin`` or
``.txt``) and ``images/``), or a nerfstudio ``transforms.json`` (the file, or its folder).

Their images are read as stored, without the EXIF orientation: that is what COLMAP and
nerfstudio read, so their poses and intrinsics belong to those pixels.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from dataset.importers.photos.posed import (
    PosedPhoto,
    PosedPhotos,
    from_reconstruction,
    sparse_points,
)

MODEL_FILES = ("cameras", "images", "points3D")
TRANSFORMS_FILE = "transforms.json"
_NERFSTUDIO_DISTORTION = ("k1", "k2", "p1", "p2", "k3", "k4")


def colmap_model_folder(path: str | Path) -> Path | None:
    """The model folder of the COLMAP project at ``path`` (``sparse/0`` or ``sparse``), or
    ``None`` when ``path`` is no such project (never raises)."""
    path = Path(path)
    if not (path / "images").is_dir():
        return None
    for model in (path / "sparse" / "0", path / "sparse"):
        if all((model / f"{n}.bin").is_file() or (model / f"{n}.txt").is_file()
               for n in MODEL_FILES):
            return model
    return None


def transforms_file(path: str | Path) -> Path | None:
    """The nerfstudio ``transforms.json`` at ``path`` (the file or its folder), or ``None``."""
    path = Path(path)
    candidate = path / TRANSFORMS_FILE if path.is_dir() else path
    return candidate if candidate.name == TRANSFORMS_FILE and candidate.is_file() else None


def read_colmap_project(path: Path) -> PosedPhotos:
    """The registered images of the COLMAP project at ``path``, with its points.

    Raises
    ------
    ValueError
        No model there, an unreadable model or a missing image.
    """
    import pycolmap  # imported here: half a second, for this source alone

    folder = colmap_model_folder(path)
    if folder is None:
        raise ValueError(f"{path} holds no COLMAP model (sparse/0/ with cameras, images and "
                         "points3D, and images/ beside it)")
    try:
        model = pycolmap.Reconstruction(folder)
    except (RuntimeError, ValueError) as exc:
        raise ValueError(f"{folder}: COLMAP cannot read this model ({exc})") from exc
    photos = from_reconstruction(model, path / "images", upright=False)
    placed = {p.name for p in photos}
    unposed = tuple(sorted(i.name for i in model.images.values() if i.name not in placed))
    return PosedPhotos(photos, sparse_points(model), unposed,
                       {"input": "COLMAP model", "model": str(folder.relative_to(path))})


def read_nerfstudio(path: Path) -> PosedPhotos:
    """The frames of a nerfstudio ``transforms.json`` (poses OpenGL camera-to-world,
    intrinsics at the top or per frame, ``OPENCV`` distortion ``k1 k2 p1 p2``, and ``k3
    k4`` as COLMAP's ``FULL_OPENCV``); no points.

    Raises
    ------
    ValueError
        A missing or malformed file, a fisheye camera, or a missing image.
    """
    file = transforms_file(path)
    if file is None:
        raise ValueError(f"{path}: no {TRANSFORMS_FILE}")
    try:
        meta = json.loads(file.read_text())
        photos = tuple(_frame(file.parent, meta, fr) for fr in meta["frames"])
    except (json.JSONDecodeError, UnicodeDecodeError, KeyError, TypeError,
            AttributeError) as exc:
        raise ValueError(f"{file} is malformed: {exc!r}") from exc
    return PosedPhotos(photos, None, (), {"input": "nerfstudio transforms.json"})


def _frame(root: Path, meta: dict[str, Any], frame: dict[str, Any]) -> PosedPhoto:
    import pycolmap

    def get(key: str, default: Any = None) -> Any:
        return frame.get(key, meta.get(key, default))

    model = str(get("camera_model", "OPENCV"))
    if model != "OPENCV":
        raise ValueError(f"camera_model {model!r} is not read (OPENCV cameras only)")
    width, height = int(get("w")), int(get("h"))
    fx, fy, cx, cy = (float(get(k)) for k in ("fl_x", "fl_y", "cx", "cy"))
    k1, k2, p1, p2, k3, k4 = (float(get(k, 0.0)) for k in _NERFSTUDIO_DISTORTION)
    if k3 == 0 and k4 == 0:
        camera = pycolmap.Camera.create_from_model_name(0, "OPENCV", fx, width, height)
        camera.params = [fx, fy, cx, cy, k1, k2, p1, p2]
    else:
        camera = pycolmap.Camera.create_from_model_name(0, "FULL_OPENCV", fx, width, height)
        camera.params = [fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, 0.0, 0.0]
    pose = np.asarray(frame["transform_matrix"], dtype=np.float64)
    if pose.shape == (3, 4):
        pose = np.vstack([pose, [0.0, 0.0, 0.0, 1.0]])
    if pose.shape != (4, 4):
        raise ValueError(f"frame {frame.get('file_path')}: transform_matrix is not 4x4")
    image = root / str(frame["file_path"])
    if not image.is_file():
        raise ValueError(f"{image}: the frame's image is not there")
    return PosedPhoto(image.name, image, False, camera, pose)
