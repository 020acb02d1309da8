"""A ``meta_data.json`` parsed once, for every layout that writes one.

sdfstudio, the BuildNet3D dataparser and both official BuildNet3D generators all write a
``meta_data.json`` with ``width``, ``height`` and ``frames[]`` (``rgb_path``, a pose,
``intrinsics``, and optional ``segmentation_path``, ``depth_path``, ...); they differ in a
pose key, camera conventions and folders. :func:`read_meta_data_file` is the one reader of
the file: it checks the structure and gives typed records
(:class:`MetaData`, :class:`MetaDataFrame`); what a layout makes of them is its reader's:
:func:`dataset.importers.buildnet3d.meta_data.read_meta_data` (sdfstudio / dataparser -> a scene),
:mod:`dataset.importers.buildnet3d.blenderproc`, :mod:`dataset.importers.buildnet3d.buildnet3d`.
:func:`read_json_file` reads every JSON file of the official layouts.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np

from envelope.camera import Intrinsics

PoseKey = Literal["camtoworld", "camera_to_world"]
META_DATA_FILE = "meta_data.json"


@dataclass(frozen=True)
class MetaDataFrame:
    """One frame of a ``meta_data.json`` as the file states it.

    ``camera_to_world`` (4, 4) is the pose as written (its camera axes are the layout's
    convention); ``pose_key`` the key it was under: ``camtoworld`` (sdfstudio, the BuildNet3D
    dataparser and Blender generator) or ``camera_to_world`` (the BlenderProc generator, whose
    K puts pixel centres at integers). ``K`` (3, 3) from the 3x3 or 4x4 ``intrinsics``.
    Paths as written, relative to the layout's folders; ``normals_path`` is read from
    ``normals_path`` or ``normal_path``.
    """

    rgb_path: str
    camera_to_world: np.ndarray
    pose_key: PoseKey
    K: np.ndarray
    segmentation_path: str | None = None
    depth_path: str | None = None
    normals_path: str | None = None
    instance_path: str | None = None
    split: str | None = None
    facade_id: int | None = None


@dataclass(frozen=True)
class MetaData:
    """A ``meta_data.json``, parsed once (:func:`read_meta_data_file`): the image size, the
    frames, and every other top-level key as written (``scene_box``, ``worldtogt``, ...)."""

    file: Path
    width: int
    height: int
    frames: tuple[MetaDataFrame, ...]
    other: dict[str, Any]

    def intrinsics(self, frame: MetaDataFrame, pixel_shift: float = 0.0) -> Intrinsics:
        """The frame's intrinsics at the file's image size, ``cx, cy`` moved by
        ``pixel_shift`` pixels (BlenderProc's pixel centres are at integers, ours at +0.5)."""
        k = frame.K
        return Intrinsics(float(k[0, 0]), float(k[1, 1]), float(k[0, 2]) + pixel_shift,
                          float(k[1, 2]) + pixel_shift, self.width, self.height)


def read_json_file(path: Path, missing: str = "", *, what: str = "valid JSON") -> Any:
    """The JSON value in ``path``; ``ValueError`` if it is missing (``missing`` says why that
    matters) or not JSON (``what`` names what it should be). The one JSON reader of the
    official layouts' files."""
    if not path.is_file():
        raise ValueError(f"{path} does not exist{missing}")
    try:
        return json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise ValueError(f"{path} is not {what}: {exc}") from None


def read_meta_data_file(path: str | Path) -> MetaData:
    """Parse a ``meta_data.json`` (or the folder holding one): the one reader of the file,
    for every layout (sdfstudio, the BuildNet3D dataparser and both generators).

    Raises
    ------
    ValueError
        Missing file, malformed JSON, no ``width``/``height``/``frames``, no frame, or a
        frame lacking ``rgb_path``, a pose (``camtoworld`` or ``camera_to_world``, 4x4 or
        3x4) or ``intrinsics`` (3x3 or 4x4).
    """
    path = Path(path)
    file = path / META_DATA_FILE if path.is_dir() else path
    meta = read_json_file(file, "; pass a meta_data.json or the folder holding one",
                          what="a valid meta_data.json")
    try:
        width, height = int(meta["width"]), int(meta["height"])
        frames = tuple(_frame_record(fr) for fr in meta["frames"])
    except (KeyError, TypeError, ValueError, AttributeError, OverflowError) as exc:
        raise ValueError(f"{file} is not a valid meta_data.json: {exc!r}") from None
    if not frames:
        raise ValueError(f"{file} has no frames")
    other = {k: v for k, v in meta.items() if k not in ("width", "height", "frames")}
    return MetaData(file, width, height, frames, other)


def _frame_record(fr: dict[str, Any]) -> MetaDataFrame:
    name = fr.get("rgb_path", "?")
    key: PoseKey = "camtoworld" if "camtoworld" in fr else "camera_to_world"
    pose = np.asarray(fr[key], dtype=np.float64)
    if pose.shape == (3, 4):
        pose = np.vstack([pose, [0.0, 0.0, 0.0, 1.0]])
    k = np.asarray(fr["intrinsics"], dtype=np.float64)
    if pose.shape != (4, 4) or k.shape not in ((3, 3), (4, 4)):
        raise ValueError(f"frame {name}: the pose must be 4x4 or 3x4 and the intrinsics 3x3 "
                         f"or 4x4, got {pose.shape} and {k.shape}")
    facade = fr.get("facade_id")
    return MetaDataFrame(
        rgb_path=str(fr["rgb_path"]), camera_to_world=pose, pose_key=key, K=k[:3, :3],
        segmentation_path=fr.get("segmentation_path"), depth_path=fr.get("depth_path"),
        normals_path=fr.get("normals_path", fr.get("normal_path")),
        instance_path=fr.get("instance_path"), split=fr.get("split"),
        facade_id=int(facade) if facade is not None else None)
