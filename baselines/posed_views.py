"""Posed views without facade ids (orbit or street views): labels, depth and world geometry.

Where no frame of a split says which facade it was taken of (``facade_id`` in
``transforms.json``: the orbit ``train`` views, a street capture), the 2D methods find the
facades themselves (:mod:`baselines.own_facades`). They read what :mod:`baselines.views`
reads, the semantic mask, the z-depth, the intrinsics and the OpenGL camera-to-world pose,
and put every pixel in the world frame.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from envelope.camera import Intrinsics, pixel_centres, unproject_depth_to_world
from envelope.classes import SemanticClass
from envelope.method_input import MethodInput, require_method_input
from envelope.protocols import OWN_FACADE_PROTOCOLS
from envelope.scene_record import Frame, scene_name
from envelope.scenes.scene_validation import (
    InvalidSceneError,
    read_frame_depth_m,
    read_frame_labels,
)

FACADE_CLASSES = (SemanticClass.WALL, SemanticClass.WINDOW, SemanticClass.DOOR)


@dataclass(frozen=True)
class PosedView:
    """One posed photo: ``labels`` (H, W) uint8 class ids, ``depth_z_m`` (H, W) float z-depth
    (m, 0 = none); ``index`` numbers the split's usable views in file order."""

    scene: str
    index: int
    frame: Frame
    labels: np.ndarray
    depth_z_m: np.ndarray

    @property
    def intrinsics(self) -> Intrinsics:
        return self.frame.intrinsics

    @property
    def camera_m(self) -> np.ndarray:
        """(3,) camera centre in the world frame (m)."""
        return np.asarray(self.frame.world_from_camera, dtype=np.float64)[:3, 3]

    @property
    def name(self) -> str:
        return f"{self.scene}: view {self.frame.file_path}"

    def world_points_m(self) -> np.ndarray:
        """(H, W, 3) world points (m) of every pixel centre at its depth (the camera centre
        where the depth is 0)."""
        return unproject_depth_to_world(pixel_centres(self.intrinsics), self.depth_z_m,
                                        self.intrinsics, self.frame.world_from_camera)

    def facade_pixels(self) -> np.ndarray:
        """(H, W) bool: wall, window or door pixels with depth."""
        return np.isin(self.labels, FACADE_CLASSES) & (self.depth_z_m > 0)


@dataclass
class PosedViews:
    """The usable views of a split and one warning per skipped view (naming it and why)."""

    views: list[PosedView] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)

    def skip(self, view_name: str, reason: str) -> None:
        self.warnings.append(f"{view_name} skipped: {reason}")


def finds_own_facades(scene: MethodInput, split: str) -> bool:
    """Whether the 2D methods find the facades themselves on ``split``: a protocol declared
    so (:data:`envelope.protocols.OWN_FACADE_PROTOCOLS`) or a split none of whose frames
    names the facade it was taken of."""
    return split in OWN_FACADE_PROTOCOLS or all(f.facade_id is None
                                                for f in scene.frames_in(split))


def load_posed_views(scene: MethodInput, split: str) -> PosedViews:
    """Read the semantic and depth images of every frame of ``split``.

    A view without a semantic mask, without readable depth or without a facade pixel with
    depth is skipped with a warning. Depth may cover part of the building only (a photos
    scene's depth comes from the sparse points of structure from motion, docs/importing.md
    section 9): its holes are pixels without depth, not a scene error, so the share of the
    building with depth is not checked here.

    Raises
    ------
    ValueError
        If the scene has no frame of ``split``.
    InvalidSceneError
        If an image is corrupt (a bad scene, not a view to skip).
    TypeError
        If ``scene`` is not a :class:`MethodInput`.
    """
    require_method_input(scene, "a 2D method")
    name = scene_name(scene)
    frames = scene.frames_in(split)
    if not frames:
        raise ValueError(f"scene {name} has no {split} views (no frame with split {split!r} in "
                         f"{scene.root / 'transforms.json'})")
    out = PosedViews()
    for frame in frames:
        view_name = f"{name}: view {frame.file_path}"
        try:
            labels = read_frame_labels(scene, frame)
            depth = read_frame_depth_m(scene, frame)
        except InvalidSceneError:
            raise
        except ValueError as exc:  # no semantic mask or no (readable) depth
            out.skip(view_name, str(exc))
            continue
        view = PosedView(name, len(out.views), frame, labels, depth)
        if not view.facade_pixels().any():
            out.skip(view_name, "no wall, window or door pixel with depth")
            continue
        out.views.append(view)
    return out
