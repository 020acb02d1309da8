"""Rectify facades to fronto-parallel rectangles of aspect L/H and measure WWR there (2D-SS).

Every view of a run is warped (kornia, nearest neighbour, in batches) onto one
square canvas of ``canvas_px`` pixels: the facade's rectangle fills the canvas
along its longer side, so its shape is ``rectangle_size_px(L / H)``; canvas
pixels outside the rectangle are marked :data:`OUTSIDE`.

Coordinates: ours are continuous with pixel centres at +0.5 (dataset.camera);
kornia puts pixel centres at integers (``align_corners=True``), hence the 0.5 shifts.
"""

from __future__ import annotations

import numpy as np
import torch
from kornia.geometry.transform import get_perspective_transform, warp_perspective

from dataset.classes import FACADE_CLASSES, SemanticClass

OUTSIDE = 255  # label of rectified-canvas pixels outside the facade rectangle


def rectangle_size_px(aspect: float, canvas_px: int) -> tuple[int, int]:
    """(width, height) in pixels of a rectangle of aspect width/height that fits the canvas."""
    if not np.isfinite(aspect) or aspect <= 0:
        raise ValueError(f"aspect ratio must be a positive number, got {aspect}")
    if canvas_px < 2:
        raise ValueError(f"canvas_px must be >= 2, got {canvas_px}")
    if aspect >= 1:
        return canvas_px, max(1, round(canvas_px / aspect))
    return max(1, round(canvas_px * aspect)), canvas_px


def rectified_from_image(corners_uv: np.ndarray, sizes_px: np.ndarray) -> torch.Tensor:
    """Homographies mapping image corners onto rectangle corners, in our pixel convention.

    Parameters
    ----------
    corners_uv : (B, 4, 2) float
        Image corners top-left, top-right, bottom-right, bottom-left.
    sizes_px : (B, 2) int
        Rectangle (width, height); the rectangle spans [0, w] x [0, h].

    Returns
    -------
    "(B, 3, 3)" float64 tensor H with ``rect ~ H @ (u, v, 1)``.
    """
    src = torch.as_tensor(np.asarray(corners_uv, dtype=np.float64))
    if src.ndim != 3 or src.shape[1:] != (4, 2):
        raise ValueError(f"corners must be (B, 4, 2), got {tuple(src.shape)}")
    dst = _rectangle_corners(np.asarray(sizes_px, dtype=np.float64))
    return get_perspective_transform(src, torch.as_tensor(dst))


def rectify_labels(
    labels: np.ndarray,
    corners_uv: np.ndarray,
    sizes_px: np.ndarray,
    canvas_px: int,
    device: torch.device | str = "cpu",
) -> np.ndarray:
    """Warp label images onto fronto-parallel rectangles (nearest neighbour).

    Parameters
    ----------
    labels : (B, H, W) uint8 class ids (all of one image size)
    corners_uv : (B, 4, 2) float image corners, top-left first, clockwise on screen
    sizes_px : (B, 2) int rectangle (width, height), each <= canvas_px

    Returns
    -------
    (B, canvas_px, canvas_px) uint8 rectified labels; :data:`OUTSIDE` beyond each rectangle.
    """
    labels = np.asarray(labels)
    sizes = np.asarray(sizes_px, dtype=np.int64)
    if labels.ndim != 3:
        raise ValueError(f"labels must be (B, H, W), got {labels.shape}")
    if sizes.shape != (len(labels), 2) or sizes.min() < 1 or sizes.max() > canvas_px:
        raise ValueError(f"sizes must be (B, 2) in 1..{canvas_px}, got {sizes.tolist()}")
    # kornia puts pixel centres at integers, we at +0.5: conjugate by that shift.
    shift = torch.eye(3, dtype=torch.float64)
    shift[:2, 2] = -0.5
    h = shift @ rectified_from_image(corners_uv, sizes) @ torch.linalg.inv(shift)
    h = h.to(device=device, dtype=torch.float32)
    img = torch.as_tensor(labels, device=device).to(torch.float32)[:, None]
    warped = warp_perspective(img, h, (canvas_px, canvas_px), mode="nearest",
                              padding_mode="zeros", align_corners=True)
    out = warped[:, 0].round().to(torch.uint8)
    cols = torch.arange(canvas_px, device=device)
    sizes_t = torch.as_tensor(sizes, device=device)
    inside = (cols[None, None, :] < sizes_t[:, 0, None, None]) & (
        cols[None, :, None] < sizes_t[:, 1, None, None]
    )
    out[~inside] = OUTSIDE
    return out.cpu().numpy()


def rectified_wwr(rectified: np.ndarray) -> np.ndarray:
    """(B,) window pixels / facade (wall + window + door) pixels of (B, S, S) rectified labels.

    NaN where a rectangle holds no facade pixel.
    """
    r = np.asarray(rectified)
    if r.ndim != 3:
        raise ValueError(f"rectified labels must be (B, S, S), got {r.shape}")
    window = (r == SemanticClass.WINDOW).sum(axis=(1, 2))
    facade = np.isin(r, [int(c) for c in FACADE_CLASSES]).sum(axis=(1, 2))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(facade > 0, window / np.maximum(facade, 1), np.nan)


def _rectangle_corners(sizes: np.ndarray) -> np.ndarray:
    """(B, 4, 2) corners (0,0), (w,0), (w,h), (0,h) of rectangles of (B, 2) sizes."""
    w, h = sizes[:, 0], sizes[:, 1]
    z = np.zeros_like(w)
    return np.stack([np.stack([z, z], -1), np.stack([w, z], -1),
                     np.stack([w, h], -1), np.stack([z, h], -1)], axis=1)
