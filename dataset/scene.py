"""One building's scene folder in memory, and ``transforms.json`` I/O (DESIGN.md).

Every method reads scenes through this module. Paths in a :class:`Frame` are
relative to the scene folder, as in ``transforms.json``.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Literal

import numpy as np

from dataset.atomic import write_json_atomic
from dataset.camera import Intrinsics
from dataset.classes import CLASS_NAMES
from dataset.scene_validation import validate_scene
from dataset.truth import BuildingTruth, read_building

Split = Literal["train", "eval", "ideal", "multi"]  # eval + the protocols (dataset.protocols)
SPLITS: tuple[str, ...] = ("train", "eval", "ideal", "multi")
DEFAULT_DEPTH_UNIT_M = 0.001  # 16-bit depth PNG in millimetres: up to 65.5 m
DEPTH_RELATIVE_STEP_KEY = "depth_relative_step"
"""Optional top-level ``transforms.json`` key: the depth's quantisation step as a fraction
of the depth, where its source was coarser than the PNG unit (Radiance HDR: 1/128)."""


@dataclass(frozen=True)
class Frame:
    """One posed image and its companion files.

    ``world_from_camera`` is the (4, 4) camera-to-world pose, OpenGL convention.
    ``facade_id`` is set for ideal and multi views only. Companion paths are
    ``None`` when the scene has no such file (a user's photos, say).
    """

    file_path: str
    world_from_camera: np.ndarray
    intrinsics: Intrinsics
    split: Split
    facade_id: int | None = None
    depth_file_path: str | None = None
    semantic_file_path: str | None = None
    normal_file_path: str | None = None
    instance_file_path: str | None = None


@dataclass(frozen=True)
class Scene:
    """A scene folder: frames, classes, depth scale and (if present) the ground truth."""

    root: Path
    frames: tuple[Frame, ...]
    semantic_classes: tuple[str, ...] = CLASS_NAMES
    depth_unit_scale_factor: float = DEFAULT_DEPTH_UNIT_M
    building: BuildingTruth | None = None
    extra: dict[str, Any] = field(default_factory=dict)

    def frames_in(self, split: Split) -> tuple[Frame, ...]:
        """Frames of one split, in file order."""
        return tuple(f for f in self.frames if f.split == split)

    def path(self, relative: str) -> Path:
        """Absolute path of a file named relative to the scene folder."""
        return self.root / relative


def read_scene(root: str | Path, *, validate: bool = True) -> Scene:
    """Read a scene folder: ``transforms.json`` and, if present, ``building.json``.

    The scene is validated (:func:`dataset.scene_validation.validate_scene`): paths
    inside the folder, finite proper poses and intrinsics, every image present with
    its declared size. ``validate=False`` is for tools that only read the JSON (a
    method must never pass it).

    Raises
    ------
    ValueError
        If the folder or its ``transforms.json`` is missing or malformed, or the scene
        is invalid (:class:`dataset.scene_validation.InvalidSceneError`).
    """
    root = Path(root)
    tf = root / "transforms.json"
    if not tf.is_file():
        raise ValueError(
            f"{root} is not a scene folder: no transforms.json (make one with "
            "`python -m dataset.generate`)"
        )
    try:
        meta = json.loads(tf.read_text())
        frames = tuple(_frame_from_json(fr, meta) for fr in meta["frames"])
        classes = tuple(str(c) for c in meta.get("semantic_classes", CLASS_NAMES))
        unit = float(meta.get("depth_unit_scale_factor", DEFAULT_DEPTH_UNIT_M))
    except (json.JSONDecodeError, UnicodeDecodeError, KeyError, TypeError, ValueError,
            AttributeError, OverflowError) as exc:
        raise ValueError(f"{tf} is malformed: {exc}") from exc
    building_json = root / "building.json"
    known = {
        "fl_x", "fl_y", "cx", "cy", "w", "h", "camera_model", "frames",
        "semantic_classes", "depth_unit_scale_factor",
    }
    scene = Scene(
        root=root,
        frames=frames,
        semantic_classes=classes,
        depth_unit_scale_factor=unit,
        building=read_building(building_json) if building_json.is_file() else None,
        extra={k: v for k, v in meta.items() if k not in known},
    )
    if validate:
        validate_scene(scene)
    return scene


def write_transforms(root: str | Path, scene: Scene) -> None:
    """Write ``transforms.json`` for ``scene`` into ``root`` (atomically).

    Intrinsics shared by all frames go to the top level (nerfstudio keys);
    frames that differ carry their own ``fl_x`` ... ``h``.
    """
    if not scene.frames:
        raise ValueError("a scene needs at least one frame")
    shared = scene.frames[0].intrinsics
    meta: dict[str, Any] = {
        "camera_model": "OPENCV",
        **_intrinsics_to_json(shared),
        "depth_unit_scale_factor": scene.depth_unit_scale_factor,
        "semantic_classes": list(scene.semantic_classes),
        **scene.extra,
        "frames": [],
    }
    for fr in scene.frames:
        d: dict[str, Any] = {
            "file_path": fr.file_path,
            "transform_matrix": np.asarray(fr.world_from_camera, dtype=float).tolist(),
            "split": fr.split,
        }
        if fr.intrinsics != shared:
            d.update(_intrinsics_to_json(fr.intrinsics))
        for key in ("depth_file_path", "semantic_file_path", "normal_file_path",
                    "instance_file_path"):
            if getattr(fr, key) is not None:
                d[key] = getattr(fr, key)
        if fr.facade_id is not None:
            d["facade_id"] = int(fr.facade_id)
        meta["frames"].append(d)
    write_json_atomic(Path(root) / "transforms.json", meta)


def with_root(scene: Scene, root: str | Path) -> Scene:
    """The same scene placed at another folder (paths stay relative)."""
    return replace(scene, root=Path(root))


def _intrinsics_to_json(k: Intrinsics) -> dict[str, Any]:
    return {"fl_x": k.fx, "fl_y": k.fy, "cx": k.cx, "cy": k.cy, "w": k.width, "h": k.height}


def _frame_from_json(fr: dict[str, Any], meta: dict[str, Any]) -> Frame:
    def get(key: str) -> Any:
        return fr[key] if key in fr else meta[key]

    intr = Intrinsics(
        float(get("fl_x")), float(get("fl_y")), float(get("cx")), float(get("cy")),
        int(get("w")), int(get("h")),
    )
    pose = np.asarray(fr["transform_matrix"], dtype=np.float64)
    if pose.shape != (4, 4):
        raise ValueError(f"frame {fr.get('file_path')}: transform_matrix must be 4x4")
    split = fr.get("split", "train")
    if split not in SPLITS:
        raise ValueError(f"frame {fr.get('file_path')}: unknown split {split!r}")
    return Frame(
        file_path=fr["file_path"],
        world_from_camera=pose,
        intrinsics=intr,
        split=split,
        facade_id=int(fr["facade_id"]) if fr.get("facade_id") is not None else None,
        depth_file_path=fr.get("depth_file_path"),
        semantic_file_path=fr.get("semantic_file_path"),
        normal_file_path=fr.get("normal_file_path"),
        instance_file_path=fr.get("instance_file_path"),
    )
