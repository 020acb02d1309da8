"""Debug images of the 2D pipelines: facade mask, corners on the view, rectified facade.

Names are predictable so that figures can pick them up:
``<scene>__<protocol>__f<facade>__v<k>__{mask,corners,rectified}.png`` with
``k`` the view's index among the views of that facade (file order).
"""

from __future__ import annotations

from pathlib import Path
from typing import Literal

import cv2
import numpy as np

from baselines.rectify import OUTSIDE
from envelope.classes import CLASS_RGB
from envelope.scenes.images import write_rgb

Kind = Literal["mask", "corners", "rectified"]

# RGB colours of the class ids (envelope.classes.CLASS_RGB) and of OUTSIDE.
_PALETTE = np.zeros((256, 3), dtype=np.uint8)
_PALETTE[:len(CLASS_RGB)] = CLASS_RGB
_PALETTE[OUTSIDE] = (255, 255, 255)


def debug_image_path(folder: Path, scene: str, protocol: str, facade_id: int, view_index: int,
                     kind: Kind) -> Path:
    """Path of one debug image."""
    return Path(folder) / f"{scene}__{protocol}__f{facade_id}__v{view_index}__{kind}.png"


def colour_labels(labels: np.ndarray, mask: np.ndarray | None = None) -> np.ndarray:
    """(H, W, 3) uint8 colour image of (H, W) class ids; pixels outside ``mask`` are dimmed."""
    rgb = _PALETTE[np.asarray(labels, dtype=np.uint8)]
    if mask is not None:
        rgb = np.where(np.asarray(mask, bool)[..., None], rgb, rgb // 4)
    return rgb


def draw_corners(image_rgb: np.ndarray, corners_uv: np.ndarray) -> np.ndarray:
    """(H, W, 3) uint8 copy of the image with the quadrilateral and its numbered corners."""
    img = np.ascontiguousarray(image_rgb).copy()
    scale = 16  # cv2 draws with 4 fractional bits, so sub-pixel corners stay put
    pts = np.round((np.asarray(corners_uv) - 0.5) * scale).astype(np.int32)
    thick = max(1, img.shape[1] // 256)
    cv2.polylines(img, [pts.reshape(-1, 1, 2)], True, (255, 40, 40), thick, cv2.LINE_AA, shift=4)
    for i, p in enumerate(pts):
        cv2.circle(img, tuple(int(x) for x in p), 4 * thick * scale, (255, 220, 0), -1,
                   cv2.LINE_AA, shift=4)
        cv2.putText(img, str(i), (int(p[0] // scale) + 6, int(p[1] // scale) - 6),
                    cv2.FONT_HERSHEY_SIMPLEX, 0.4 * thick, (255, 220, 0), thick, cv2.LINE_AA)
    return img


def write_debug_image(folder: Path, scene: str, protocol: str, facade_id: int,
                      view_index: int, kind: Kind, image_rgb: np.ndarray) -> Path:
    """Write one (H, W, 3) uint8 debug image atomically; returns its path."""
    path = debug_image_path(folder, scene, protocol, facade_id, view_index, kind)
    write_rgb(path, image_rgb)
    return path
