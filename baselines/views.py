"""Load the facade views of one protocol (ideal or multi) and skip bad ones with a reason.

A 2D method sees only what a person with a camera would have: the semantic
mask, the intrinsics, the pose, the facade the photo was taken of
(``facade_id`` in ``transforms.json``) and, where the method needs it, the
depth image. It never reads facade-id images, ``mesh.ply`` or ``building.json``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from envelope.camera import Intrinsics
from envelope.method_input import MethodInput, require_method_input
from envelope.protocols import VIEW_PROTOCOLS, ViewProtocol
from envelope.scene_record import Frame, scene_name
from envelope.scenes.scene_validation import (
    InvalidSceneError,
    read_frame_depth_m,
    read_frame_labels,
)

Protocol = ViewProtocol  # the 2D methods' protocols (envelope.protocols)


class ViewError(ValueError):
    """A view cannot be used; the message says why (it becomes a warning, not a failure)."""


@dataclass(frozen=True)
class FacadeView:
    """One photo of one facade.

    ``view_index`` numbers the views of the same facade in file order (the ``k``
    of the debug image names). ``labels`` is (H, W) uint8 class ids;
    ``depth_z_m`` is (H, W) float32 z-depth in metres (0 = none) or ``None``
    when the method did not ask for depth or the scene has none.
    """

    scene: str
    facade_id: int
    view_index: int
    frame: Frame
    labels: np.ndarray
    depth_z_m: np.ndarray | None

    @property
    def intrinsics(self) -> Intrinsics:
        return self.frame.intrinsics

    @property
    def name(self) -> str:
        """How warnings name this view: its image file and facade."""
        return f"{self.scene}: view {self.frame.file_path} (facade {self.facade_id})"


@dataclass
class LoadedViews:
    """The usable views of a run, the facades they show and what was skipped.

    ``facade_ids`` holds every facade named by a frame of the protocol, usable
    or not, so that a facade without a usable view is reported as missing.
    ``skipped`` maps a facade id to the reasons its views were skipped.
    """

    views: list[FacadeView] = field(default_factory=list)
    facade_ids: list[int] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    skipped: dict[int, list[str]] = field(default_factory=dict)

    def skip(self, view_name: str, facade_id: int | None, reason: str) -> None:
        """Record one skipped view: one warning naming the view and the reason."""
        self.warnings.append(f"{view_name} skipped: {reason}")
        if facade_id is not None:
            self.skipped.setdefault(facade_id, []).append(reason)


def load_views(scene: MethodInput, protocol: Protocol, *, depth: Literal["required", "optional",
               "no"]) -> LoadedViews:
    """Read the semantic (and depth) images of every frame of ``protocol``.

    Parameters
    ----------
    depth : "required" | "optional" | "no"
        "required": a view without readable depth is skipped (2D-SS);
        "optional": a view keeps ``depth_z_m=None`` and a warning says why (2D-S);
        "no": depth is not read.

    Raises
    ------
    ValueError
        If ``protocol`` is not "ideal" or "multi", or the scene has no frame of it.
    TypeError
        If ``scene`` is not a :class:`MethodInput` (a ``Scene`` holds the truth).
    """
    require_method_input(scene, "a 2D method")
    if protocol not in VIEW_PROTOCOLS:
        raise ValueError(f"unknown view protocol {protocol!r}; expected one of {VIEW_PROTOCOLS}")
    if depth not in ("required", "optional", "no"):
        raise ValueError(f"depth must be 'required', 'optional' or 'no', got {depth!r}")
    name = scene_name(scene)
    frames = scene.frames_in(protocol)
    if not frames:
        raise ValueError(
            f"scene {name} has no {protocol} views (no frame with split {protocol!r} in "
            f"{scene.root / 'transforms.json'})"
        )
    out = LoadedViews()
    counts: dict[int, int] = {}
    for frame in frames:
        fid = frame.facade_id
        if fid is None:
            out.skip(f"{name}: view {frame.file_path}", None,
                     "the frame has no facade_id in transforms.json")
            continue
        if fid not in counts:
            counts[fid] = 0
            out.facade_ids.append(fid)
        k = counts[fid]
        counts[fid] += 1
        view_name = f"{name}: view {frame.file_path} (facade {fid})"
        try:
            labels = _read_labels(scene, frame)
            depth_z_m = None if depth == "no" else _read_depth(scene, frame, labels)
        except InvalidSceneError:  # a bad file is a bad scene, not a view to skip
            raise
        except ViewError as exc:
            out.skip(view_name, fid, str(exc))
            continue
        except ValueError as exc:  # missing or unreadable depth
            if depth == "required":
                out.skip(view_name, fid, str(exc))
                continue
            out.warnings.append(f"{view_name}: no area scale: {exc}")
            depth_z_m = None
        out.views.append(FacadeView(name, fid, k, frame, labels, depth_z_m))
    return out


def _read_labels(scene: MethodInput, frame: Frame) -> np.ndarray:
    if frame.semantic_file_path is None:
        raise ViewError("the frame has no semantic_file_path (semantic mask) in transforms.json")
    return read_frame_labels(scene, frame)


def _read_depth(scene: MethodInput, frame: Frame, labels: np.ndarray) -> np.ndarray:
    """Raises plain ValueError (not ViewError) so that callers decide whether depth matters."""
    return read_frame_depth_m(scene, frame, labels)
