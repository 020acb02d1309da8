"""The sdfstudio ``meta_data.json`` layout (used by the public BuildNet3D data) <-> :class:`Scene`.

sdfstudio's file: top-level ``camera_model``, ``height``, ``width``, ``has_mono_prior``,
``worldtogt`` (4x4), ``scene_box`` (``aabb``, ``near``, ``far``, ``radius``,
``collider_type``) and ``frames[]`` with ``rgb_path``, ``camtoworld`` (4x4) and
``intrinsics`` (4x4 or 3x3: fx, fy, cx, cy). BuildNet3D frames add ``segmentation_path``
(and ``depth_path``). Conventions differ between the two, so they are a parameter
(:class:`MetaDataLayout`):

- sdfstudio's dataparser reads ``camtoworld`` as OpenCV (x right, y down, looking along
  +z) and flips it to OpenGL; paths are relative to the folder of ``meta_data.json``.
- BuildNet3D's dataparser uses ``camtoworld`` as OpenGL (its BlenderProc renderer writes
  Blender poses, its converter copies nerfstudio's ``transform_matrix``) and finds
  ``rgb_path`` under ``images/`` and ``segmentation_path`` under ``semantic/``.

Segmentation images keep the source's class ids (or colours) on disk, and the scene
declares the source's class list, so :func:`envelope.scenes.scene_validation.read_frame_labels`
remaps them
(:mod:`envelope.scenes.labels`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from typing import Any, Literal

import numpy as np

from dataset.importers.buildnet3d.meta_data_file import (
    META_DATA_FILE,
    MetaData,
    MetaDataFrame,
    read_meta_data_file,
)
from envelope.atomic import write_json_atomic
from envelope.protocols import SPLITS, TRAIN_PROTOCOL
from envelope.scene_record import DEFAULT_DEPTH_UNIT_M, Frame, Scene
from envelope.scenes.labels import (  # noqa: F401  (re-exported: the mappings lived here)
    ClassIds,
    ClassMapping,
    class_mapping,
    read_remapped_labels,
    remap_labels,
)
from envelope.scenes.scene_validation import validate_scene

PoseConvention = Literal["opencv", "opengl"]
OPENCV_FROM_OPENGL = np.diag([1.0, -1.0, -1.0, 1.0])
"""Right-multiply a camera-to-world pose by this to swap OpenGL <-> OpenCV camera axes."""


@dataclass(frozen=True)
class MetaDataLayout:
    """Where a ``meta_data.json`` flavour keeps its files and how it writes poses.

    Folders are relative to the folder of ``meta_data.json`` and are prefixed to the
    frame's paths on reading (and stripped on writing). ``normals_key`` is the key a frame's
    normal image is written under (either key is read).
    """

    pose_convention: PoseConvention = "opencv"
    rgb_dir: str = ""
    segmentation_dir: str = ""
    depth_dir: str = ""
    normals_key: str = "normal_path"

    def __post_init__(self) -> None:
        if self.pose_convention not in ("opencv", "opengl"):
            raise ValueError(
                f"pose_convention must be 'opencv' or 'opengl', got {self.pose_convention!r}"
            )


SDFSTUDIO_LAYOUT = MetaDataLayout()
BUILDNET3D_LAYOUT = MetaDataLayout(
    pose_convention="opengl", rgb_dir="images", segmentation_dir="semantic",
    normals_key="normals_path",  # buildnet_dataparser.py:89
)


def read_meta_data(
    path: str | Path,
    *,
    class_ids: ClassIds = "renderer",
    layout: MetaDataLayout = SDFSTUDIO_LAYOUT,
    validate: bool = True,
) -> tuple[Scene, ClassMapping]:
    """Read a ``meta_data.json`` (or the folder holding one) into a :class:`Scene`.

    Parameters
    ----------
    path
        The file, or its folder.
    class_ids
        Which ids the segmentation images hold: ``"renderer"`` (default; the public
        BuildNet3D image data), ``"generator"`` (BuildNet3D procedural generator) or
        ``"envelope_bench"`` (files written by :func:`write_meta_data`).
    layout
        :data:`SDFSTUDIO_LAYOUT` (default: OpenCV poses, paths relative to the file) or
        :data:`BUILDNET3D_LAYOUT` (OpenGL poses, ``images/`` and ``semantic/`` folders).
    validate
        Check the scene as :func:`envelope.scenes.scene.read_scene` does
        (:func:`envelope.scenes.scene_validation.validate_scene`); ``False`` only for JSON-only
        tools.

    Returns
    -------
    scene
        Frames with OpenGL ``world_from_camera`` and paths relative to the file's folder
        (segmentation images still in the source's ids, and ``semantic_classes`` the
        source's class names, so :func:`envelope.scenes.scene_validation.read_frame_labels` remaps
        them);
        split ``train`` unless a frame says otherwise. ``extra`` keeps ``scene_box``,
        ``worldtogt`` and other top-level keys.
    mapping
        The :class:`ClassMapping` to pass to :func:`remap_labels`.

    Raises
    ------
    ValueError
        Missing file, malformed JSON, a frame lacking a pose, intrinsics or image path, or
        an invalid scene (:class:`envelope.scenes.scene_validation.InvalidSceneError`).
    """
    mapping = class_mapping(class_ids)
    meta = read_meta_data_file(path)
    try:
        frames = tuple(_frame(meta, fr, layout) for fr in meta.frames)
        unit = float(meta.other.get("depth_unit_scale_factor", DEFAULT_DEPTH_UNIT_M))
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{meta.file} is not a valid meta_data.json: {exc!r}") from exc
    known = {"camera_model", "depth_unit_scale_factor", "semantic_classes"}
    scene = Scene(
        root=meta.file.parent,
        frames=frames,
        semantic_classes=mapping.names,
        depth_unit_scale_factor=unit,
        extra={k: v for k, v in meta.other.items() if k not in known},
    )
    if validate:
        validate_scene(scene)
    return scene, mapping


def write_meta_data(
    scene: Scene, path: str | Path, *, layout: MetaDataLayout = SDFSTUDIO_LAYOUT
) -> None:
    """Write ``scene`` as a ``meta_data.json`` (atomically) for sdfstudio-style tools.

    ``path`` is the file, or an existing folder to write ``meta_data.json`` into. Poses go
    out in ``layout.pose_convention``; intrinsics as 4x4. ``scene_box`` and ``worldtogt``
    come from ``scene.extra`` when present; missing entries default to the identity and
    to a box around the building (footprint x/y, 0 to its height, 10 % margin) or else
    around the cameras, ``near`` 0.05 m, ``far`` the cameras' extent, collider
    ``near_far``. Labels are written as they are: read back with
    ``class_ids="envelope_bench"``. Our ``split``, ``facade_id`` and normal/instance paths
    are kept as extra frame keys, which sdfstudio ignores.

    Raises
    ------
    ValueError
        No frames, frames of different image sizes (the layout has one size), or a
        path outside the layout's folder.
    """
    if not scene.frames:
        raise ValueError("a scene needs at least one frame")
    sizes = {(f.intrinsics.width, f.intrinsics.height) for f in scene.frames}
    if len(sizes) > 1:
        raise ValueError(
            f"meta_data.json holds one image size, but the frames have {sorted(sizes)}; "
            "resize the images to one size first"
        )
    (width, height), = sizes
    centres = np.array([np.asarray(f.world_from_camera)[:3, 3] for f in scene.frames])
    diagonal = float(np.linalg.norm(centres.max(axis=0) - centres.min(axis=0))) or 1.0
    scene_box = {
        "aabb": _scene_aabb(scene, centres),
        "near": 0.05,
        "far": diagonal,
        "radius": diagonal / 2,
        "collider_type": "near_far",
        **scene.extra.get("scene_box", {}),  # BuildNet3D's boxes have only an aabb
    }
    meta: dict[str, Any] = {
        "camera_model": "OPENCV",
        "height": height,
        "width": width,
        "has_mono_prior": False,
        "worldtogt": np.eye(4).tolist(),
        **scene.extra,
        "scene_box": scene_box,
        "depth_unit_scale_factor": scene.depth_unit_scale_factor,
        "semantic_classes": list(scene.semantic_classes),
        "frames": [_frame_to_json(f, layout) for f in scene.frames],
    }
    path = Path(path)
    write_json_atomic(path / META_DATA_FILE if path.is_dir() else path, meta)


def _scene_aabb(scene: Scene, camera_centres_m: np.ndarray) -> list[list[float]]:
    """[[x, y, z] min, max] around the building if the scene has its truth, else the cameras."""
    if scene.building is None:
        return [camera_centres_m.min(axis=0).tolist(), camera_centres_m.max(axis=0).tolist()]
    from envelope.footprint import geojson_to_polygon

    x0, y0, x1, y1 = geojson_to_polygon(scene.building.footprint).bounds
    lo, hi = np.array([x0, y0, 0.0]), np.array([x1, y1, scene.building.height_m])
    margin = 0.1 * np.linalg.norm(hi - lo)
    return [(lo - margin).tolist(), (hi + margin).tolist()]


def opencv_from_opengl(world_from_camera: np.ndarray) -> np.ndarray:
    """(4, 4) camera-to-world pose with the camera's y and z axes flipped (either direction)."""
    pose = np.asarray(world_from_camera, dtype=np.float64)
    if pose.shape != (4, 4):
        raise ValueError(f"a camera pose must be (4, 4), got shape {pose.shape}")
    return pose @ OPENCV_FROM_OPENGL


def _frame(meta: MetaData, fr: MetaDataFrame, layout: MetaDataLayout) -> Frame:
    pose = fr.camera_to_world
    if layout.pose_convention == "opencv":
        pose = opencv_from_opengl(pose)
    split = fr.split if fr.split is not None else TRAIN_PROTOCOL
    if split not in SPLITS:
        raise ValueError(f"frame {fr.rgb_path}: unknown split {split!r}; expected one of {SPLITS}")
    return Frame(
        file_path=_join(layout.rgb_dir, fr.rgb_path),
        world_from_camera=pose,
        intrinsics=meta.intrinsics(fr),
        split=split,
        facade_id=fr.facade_id,
        depth_file_path=_join(layout.depth_dir, fr.depth_path),
        semantic_file_path=_join(layout.segmentation_dir, fr.segmentation_path),
        normal_file_path=fr.normals_path,
        instance_file_path=fr.instance_path,
    )


def _frame_to_json(fr: Frame, layout: MetaDataLayout) -> dict[str, Any]:
    pose = np.asarray(fr.world_from_camera, dtype=np.float64)
    if layout.pose_convention == "opencv":
        pose = opencv_from_opengl(pose)
    k = np.eye(4)
    k[:3, :3] = fr.intrinsics.K
    d: dict[str, Any] = {
        "rgb_path": _strip(layout.rgb_dir, fr.file_path),
        "camtoworld": pose.tolist(),
        "intrinsics": k.tolist(),
    }
    for key, folder, value in (
        ("segmentation_path", layout.segmentation_dir, fr.semantic_file_path),
        ("depth_path", layout.depth_dir, fr.depth_file_path),
        (layout.normals_key, "", fr.normal_file_path),
        ("instance_path", "", fr.instance_file_path),
    ):
        if value is not None:
            d[key] = _strip(folder, value)
    d["split"] = fr.split
    if fr.facade_id is not None:
        d["facade_id"] = int(fr.facade_id)
    return d


def _join(folder: str, relative: str | None) -> str | None:
    if relative is None:
        return None
    return str(PurePosixPath(folder) / relative) if folder else relative


def _strip(folder: str, path: str) -> str:
    if not folder:
        return path
    p = PurePosixPath(path)
    try:
        return str(p.relative_to(folder))
    except ValueError:
        raise ValueError(
            f"{path} is not inside {folder}/, which this layout requires; move the file or "
            "use SDFSTUDIO_LAYOUT (paths relative to the scene folder)"
        ) from None
