"""A scene folder's ``transforms.json`` read into a :class:`~envelope.scene_record.Scene` and
written back (docs/DESIGN.md).

Methods read scenes through :func:`read_method_input`, which never opens ``building.json``;
:func:`read_scene` (the truth too) is for the dataset's tools and for metrics. Every command
finds the scene folders it was given with :func:`find_scene_folders`.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from envelope.atomic import write_json_atomic
from envelope.camera import Intrinsics
from envelope.classes import CLASS_NAMES
from envelope.method_input import ALL_INPUTS, Input, MethodInput, method_input
from envelope.protocols import SPLITS, TRAIN_PROTOCOL
from envelope.scene_record import DEFAULT_DEPTH_UNIT_M, Frame, Scene
from envelope.scenes.scene_validation import validate_scene
from envelope.truth import read_building


def find_scene_folders(folder: str | Path, *, with_images: bool = False) -> list[Path]:
    """The scene folders named by ``folder``: ``folder`` itself if it is one, else its
    sub-folders that are (one level down), sorted by name.

    A scene folder holds ``transforms.json`` (the images a method reads) or
    ``building.json`` (the truth that metrics scores against); ``with_images``: only those
    with ``transforms.json`` count (for a command that runs a method or a segmenter).
    Hidden folders (``.<name>.partial``: a copy a killed run left unfinished, see
    :func:`envelope.atomic.atomic_directory`) are no scenes.

    Raises
    ------
    ValueError
        If ``folder`` does not exist or holds no scene folder.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise ValueError(f"data folder {folder} does not exist")
    markers = ("transforms.json",) if with_images else ("transforms.json", "building.json")

    def is_scene(d: Path) -> bool:
        return any((d / m).is_file() for m in markers)

    if is_scene(folder):
        return [folder]
    scenes = sorted(d for d in folder.iterdir()
                    if d.is_dir() and not d.name.startswith(".") and is_scene(d))
    if not scenes:
        raise ValueError(
            f"{folder} holds no scene folder (one with {' or '.join(markers)}) and is none; "
            "make a benchmark with `python -m dataset.generate --preset tiny --out DIR`")
    return scenes


def read_scene(root: str | Path, *, validate: bool = True) -> Scene:
    """Read a scene folder: ``transforms.json`` and, if present, ``building.json``.

    The scene is validated (:func:`envelope.scenes.scene_validation.validate_scene`): paths
    inside the folder, finite proper poses and intrinsics, every image present with
    its declared size. ``validate=False`` is for tools that only read the JSON.

    Raises
    ------
    ValueError
        If the folder or its ``transforms.json`` is missing or malformed, the truth is
        malformed, or the scene is invalid
        (:class:`envelope.scenes.scene_validation.InvalidSceneError`).
    """
    scene = _read_transforms(Path(root))
    building_json = scene.root / "building.json"
    if building_json.is_file():
        scene = replace(scene, building=read_building(building_json))
    if validate:
        validate_scene(scene)
    return scene


def read_method_input(root: str | Path, inputs: tuple[Input, ...] = ALL_INPUTS) -> MethodInput:
    """Read a scene folder as a method declaring ``inputs`` sees it
    (:func:`envelope.method_input.method_input`), from ``transforms.json`` alone, and
    validate the files it names as :func:`read_scene` does.

    Raises
    ------
    ValueError
        As :func:`read_scene`; ``building.json``, ``mesh.ply`` and the facade-id and normal
        images are never opened, so their state changes nothing.
    """
    view = method_input(_read_transforms(Path(root)), inputs)
    validate_scene(view)
    return view


def _read_transforms(root: Path) -> Scene:
    """The scene of ``root/transforms.json``, without truth and unvalidated."""
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
    known = {
        "fl_x", "fl_y", "cx", "cy", "w", "h", "camera_model", "frames",
        "semantic_classes", "depth_unit_scale_factor",
    }
    return Scene(
        root=root,
        frames=frames,
        semantic_classes=classes,
        depth_unit_scale_factor=unit,
        extra={k: v for k, v in meta.items() if k not in known},
    )


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
    split = fr.get("split", TRAIN_PROTOCOL)
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
