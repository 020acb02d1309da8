"""Scene folder -> training pixels: images, labels and rays in the normalised frame.

Only what training may use is read: RGB, semantic masks, intrinsics, poses
(and depth for the ``depth_loss`` variant). Conversions happen here, once.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
import torch
from torch import Tensor

from envelope.camera import Intrinsics, rays_world
from envelope.classes import SemanticClass
from envelope.method_input import MethodInput
from envelope.protocols import Split
from envelope.scenes.images import read_rgb
from envelope.scenes.scene_validation import read_frame_depth_m, read_frame_labels
from neural3d.field.normalisation import Normalisation
from neural3d.training.scene_box import visual_hull_box_m


@dataclass(frozen=True)
class LoadedFrame:
    """One frame's images at the training scale (NumPy, world metres).

    rgb (H, W, 3) uint8; labels (H, W) uint8; depth_z_m (H, W) float32 or None.
    """

    file_path: str
    intrinsics: Intrinsics
    world_from_camera: np.ndarray
    rgb: np.ndarray
    labels: np.ndarray
    depth_z_m: np.ndarray | None


@dataclass(frozen=True)
class Pixels:
    """Pixels of several frames as flat tensors on one device, normalised frame.

    origins "(P, 3)", dirs "(P, 3)" unit, rgb "(P, 3)" in [0, 1], labels "(P,)" int64,
    depth_t "(P,)" distance along the ray (normalised units, NaN = none) or None.
    ``shapes``: (H, W) per frame, in order.
    """

    origins: Tensor
    dirs: Tensor
    rgb: Tensor
    labels: Tensor
    depth_t: Tensor | None
    shapes: tuple[tuple[int, int], ...]

    def __len__(self) -> int:
        return len(self.labels)


def background_class(scene: MethodInput) -> int:
    """Our background class id: :func:`envelope.scenes.scene_validation.read_frame_labels` gives
    every frame's labels in the project's ids (:data:`envelope.classes.CLASS_NAMES`), whatever
    the scene holds."""
    return int(SemanticClass.BACKGROUND)


def load_frames(scene: MethodInput, split: Split, *, image_scale: float = 1.0,
                with_depth: bool = False) -> list[LoadedFrame]:
    """Read the frames of ``split``, resized by ``image_scale``.

    Raises
    ------
    ValueError
        If the split has no frames, a frame lacks its semantic (or depth) file, an
        image's size differs from its intrinsics, or a label is not a known class.
    """
    frames = scene.frames_in(split)
    if not frames:
        raise ValueError(f"scene {scene.root} has no {split!r} frames; neural3d trains on "
                         "split='train' frames of transforms.json")
    out = []
    for fr in frames:
        if fr.semantic_file_path is None:
            raise ValueError(f"frame {fr.file_path} has no semantic_file_path: neural3d "
                             "needs a semantic mask per frame")
        if with_depth and fr.depth_file_path is None:
            raise ValueError(f"frame {fr.file_path} has no depth_file_path (needed by "
                             "depth_loss); train without --depth-loss")
        rgb = read_rgb(scene.path(fr.file_path))
        labels = read_frame_labels(scene, fr)  # size and class ids checked
        depth = read_frame_depth_m(scene, fr, labels) if with_depth else None
        k = fr.intrinsics
        if rgb.shape[:2] != (k.height, k.width):
            raise ValueError(
                f"image of frame {fr.file_path} is {rgb.shape[1]}x{rgb.shape[0]} but its "
                f"intrinsics say {k.width}x{k.height}: fix transforms.json or the image"
            )
        if image_scale != 1.0:
            k = k.scaled(image_scale)
            size = (k.width, k.height)
            rgb = cv2.resize(rgb, size, interpolation=cv2.INTER_AREA)
            labels = cv2.resize(labels, size, interpolation=cv2.INTER_NEAREST)
            if depth is not None:
                depth = cv2.resize(depth, size, interpolation=cv2.INTER_NEAREST)
        out.append(LoadedFrame(fr.file_path, k, np.asarray(fr.world_from_camera), rgb, labels,
                               depth))
    return out


def scene_normalisation(frames: list[LoadedFrame], background: int, *,
                        margin: float) -> Normalisation:
    """Normalisation whose box is the visual hull of the frames' non-background masks."""
    lo, hi = visual_hull_box_m(
        [f.intrinsics for f in frames], [f.world_from_camera for f in frames],
        [f.labels != background for f in frames], margin=margin,
    )
    return Normalisation.from_box(lo, hi)


def frames_to_pixels(frames: list[LoadedFrame], norm: Normalisation,
                     device: torch.device) -> Pixels:
    """Every pixel of ``frames`` as rays in the normalised frame, on ``device``."""
    origins, dirs, rgb, labels, depth = [], [], [], [], []
    for f in frames:
        o, d_z = rays_world(f.intrinsics, f.world_from_camera)
        o, d_z = o.reshape(-1, 3), d_z.reshape(-1, 3)
        length = np.linalg.norm(d_z, axis=1)
        origins.append((o - norm.centre_m) / norm.scale_m)
        dirs.append(d_z / length[:, None])
        rgb.append(f.rgb.reshape(-1, 3))
        labels.append(f.labels.reshape(-1))
        if f.depth_z_m is not None:
            dz = f.depth_z_m.reshape(-1).astype(np.float64)
            depth.append(np.where(dz > 0, dz * length / norm.scale_m, np.nan))

    def t(a: list[np.ndarray], dtype: torch.dtype) -> Tensor:
        return torch.as_tensor(np.concatenate(a), dtype=dtype, device=device)

    return Pixels(
        origins=t(origins, torch.float32), dirs=t(dirs, torch.float32),
        rgb=t(rgb, torch.float32) / 255.0, labels=t(labels, torch.int64),
        depth_t=t(depth, torch.float32) if len(depth) == len(frames) and depth else None,
        shapes=tuple(f.labels.shape for f in frames),
    )


