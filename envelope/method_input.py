"""What a method may read of a scene: its images, poses and intrinsics, and the depth and
semantic images it declares. Never the truth.

A :class:`~envelope.scene_record.Scene` carries the ground truth (``building``, from
``building.json``) and the generator's record (``extra``); a method gets a
:class:`MethodInput` instead, made by :func:`method_input` from a scene in memory or by
:func:`envelope.scenes.scene.read_method_input` from a folder (which never opens
``building.json``). Its frames keep the image, pose, intrinsics, split and, for facade views,
the photographed facade's id (``facade_id``: the protocol names what each photo was taken
of); the facade-id images (``instance_file_path``) and normal images, both rendered from the
true mesh, are dropped, and so are the depth and semantic images a method does not declare.
``root`` locates those files; a method opens only the paths its frames name.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Literal, get_args

from envelope.classes import CLASS_NAMES
from envelope.protocols import Split
from envelope.scene_record import (
    DEFAULT_DEPTH_UNIT_M,
    DEPTH_RELATIVE_STEP_KEY,
    Frame,
    Scene,
)

Input = Literal["rgb", "semantics", "depth", "poses"]
"""What a method may declare it reads of a scene (:attr:`envelope.method.Method.inputs`)."""
ALL_INPUTS: tuple[Input, ...] = get_args(Input)


@dataclass(frozen=True)
class MethodInput:
    """A scene as a method sees it (module docstring): frames, classes, depth scale.

    ``depth_relative_step`` is the depth's quantisation step as a fraction of the depth where
    the scene's source was coarser than its PNG unit (Radiance HDR: 1/128), else 0.
    ``inputs`` are the inputs it was made for.
    """

    root: Path
    frames: tuple[Frame, ...]
    semantic_classes: tuple[str, ...] = CLASS_NAMES
    depth_unit_scale_factor: float = DEFAULT_DEPTH_UNIT_M
    depth_relative_step: float = 0.0
    inputs: tuple[Input, ...] = ALL_INPUTS

    def frames_in(self, split: Split) -> tuple[Frame, ...]:
        """Frames of one split, in file order."""
        return tuple(f for f in self.frames if f.split == split)

    def path(self, relative: str) -> Path:
        """Absolute path of a file named relative to the scene folder."""
        return self.root / relative


def method_input(scene: Scene, inputs: tuple[Input, ...] = ALL_INPUTS) -> MethodInput:
    """``scene`` as a method declaring ``inputs`` sees it: no truth, no generator record, no
    facade-id or normal images, and depth and semantic images only if declared.

    Raises
    ------
    ValueError
        An unknown input name.
    """
    unknown = [i for i in inputs if i not in ALL_INPUTS]
    if unknown:
        raise ValueError(f"unknown method inputs {unknown}; choose from {', '.join(ALL_INPUTS)}")
    frames = tuple(replace(
        f, instance_file_path=None, normal_file_path=None,
        depth_file_path=f.depth_file_path if "depth" in inputs else None,
        semantic_file_path=f.semantic_file_path if "semantics" in inputs else None,
    ) for f in scene.frames)
    return MethodInput(
        root=scene.root, frames=frames, semantic_classes=scene.semantic_classes,
        depth_unit_scale_factor=scene.depth_unit_scale_factor,
        depth_relative_step=float(scene.extra.get(DEPTH_RELATIVE_STEP_KEY, 0.0)),
        inputs=tuple(inputs),
    )


def require_method_input(scene: object, method: str) -> MethodInput:
    """``scene`` if it is a :class:`MethodInput`; a ``TypeError`` saying how to make one if
    it is anything else (a :class:`Scene` holds the truth, which a method must not get)."""
    if not isinstance(scene, MethodInput):
        raise TypeError(
            f"{method} reads a envelope.method_input.MethodInput, got "
            f"{type(scene).__name__}: pass method_input(scene) or "
            "envelope.scenes.scene.read_method_input(folder), which hold no truth")
    return scene
