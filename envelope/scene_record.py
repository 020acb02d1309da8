"""One building's scene in memory: its posed frames, classes, depth unit and truth (docs/DESIGN.md).

Paths in a :class:`Frame` are relative to the scene folder, as in
``transforms.json`` (read and written by :mod:`envelope.scenes.scene`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from envelope.camera import Intrinsics
from envelope.classes import CLASS_NAMES
from envelope.protocols import Split
from envelope.truth import BuildingTruth

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


class InFolder(Protocol):
    """Anything read from a scene folder: a :class:`Scene`, a method's
    :class:`~envelope.method_input.MethodInput`."""

    root: Path


def scene_name(scene: InFolder | str | Path) -> str:
    """A scene's name in result files, run folders and warnings: its folder's name."""
    root = Path(scene) if isinstance(scene, (str, Path)) else scene.root
    return root.resolve().name
