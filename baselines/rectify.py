"""Rectify facades to fronto-parallel rectangles of aspect L/H and measure WWR there (2D-SS).

Each facade gets a rectangle of aspect L/H with about as many pixels as its
quadrilateral covers in the image (times ``scale``²; :func:`rectangle_size_px`):
rectifying at a finer grid than the photo adds no information, only work.
Views are warped with kornia (nearest neighbour) in batches onto a canvas as
large as the batch's largest rectangle; canvas pixels outside a view's
rectangle are marked :data:`OUTSIDE`.

Coordinates: ours are continuous with pixel centres at +0.5 (envelope.camera);
kornia puts pixel centres at integers (``align_corners=True``), hence the 0.5 shifts.
"""

from __future__ import annotations

import numpy as np
import torch
from kornia.geometry.transform import get_perspective_transform, warp_perspective

from envelope.classes import SemanticClass
from envelope.polygons import polygon_area
from envelope.wwr import wwr_from_areas

OUTSIDE = 255  # label of rectified-canvas pixels outside the facade rectangle


def rectangle_size_px(aspect: float, area_px: float, max_side_px: int) -> tuple[int, int]:
    """(width, height) of a rectangle of aspect width/height with about ``area_px`` pixels.

    The longer side is at most ``max_side_px``; each side is at least 1.
    """
    if not np.isfinite(aspect) or aspect <= 0:
        raise ValueError(f"aspect ratio must be a positive number, got {aspect}")
    if not np.isfinite(area_px) or area_px <= 0 or max_side_px < 1:
        raise ValueError(f"area_px must be > 0 and max_side_px >= 1, got {area_px}, "
                         f"{max_side_px}")
    h = np.sqrt(area_px / aspect)
    w = aspect * h
    shrink = min(1.0, max_side_px / max(w, h))
    return max(1, round(w * shrink)), max(1, round(h * shrink))


def quadrilateral_area_px(corners_uv: np.ndarray) -> float:
    """Area (px²) of a (4, 2) image quadrilateral (shoelace formula)."""
    c = np.asarray(corners_uv, dtype=np.float64)
    if c.shape != (4, 2):
        raise ValueError(f"corners must be (4, 2), got {c.shape}")
    return polygon_area(c)


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
    device: torch.device | str = "cpu",
) -> np.ndarray:
    """Warp label images onto fronto-parallel rectangles (nearest neighbour).

    Parameters
    ----------
    labels : (B, H, W) uint8 class ids (all of one image size)
    corners_uv : (B, 4, 2) float image corners, top-left first, clockwise on screen
    sizes_px : (B, 2) int rectangle (width, height), each >= 1

    Returns
    -------
    (B, max height, max width) uint8 rectified labels; :data:`OUTSIDE` beyond each rectangle.
    """
    labels = np.asarray(labels)
    sizes = np.asarray(sizes_px, dtype=np.int64)
    if labels.ndim != 3:
        raise ValueError(f"labels must be (B, H, W), got {labels.shape}")
    if sizes.shape != (len(labels), 2) or sizes.min() < 1:
        raise ValueError(f"sizes must be (B, 2) with sides >= 1, got {sizes.tolist()}")
    out_w, out_h = (int(x) for x in sizes.max(axis=0))
    # kornia puts pixel centres at integers, we at +0.5: conjugate by that shift.
    shift = torch.eye(3, dtype=torch.float64)
    shift[:2, 2] = -0.5
    h = shift @ rectified_from_image(corners_uv, sizes) @ torch.linalg.inv(shift)
    h = h.to(device=device, dtype=torch.float32)
    img = torch.as_tensor(labels, device=device).to(torch.float32)[:, None]
    warped = warp_perspective(img, h, (out_h, out_w), mode="nearest",
                              padding_mode="zeros", align_corners=True)
    out = warped[:, 0].round().to(torch.uint8)
    sizes_t = torch.as_tensor(sizes, device=device)
    cols = torch.arange(out_w, device=device)[None, None, :]
    rows = torch.arange(out_h, device=device)[None, :, None]
    inside = (cols < sizes_t[:, 0, None, None]) & (rows < sizes_t[:, 1, None, None])
    out[~inside] = OUTSIDE
    return out.cpu().numpy()


def rectified_wwr(rectified: np.ndarray) -> np.ndarray:
    """(B,) window pixels / facade (wall + window + door) pixels of (B, h, w) rectified labels.

    NaN where a rectangle holds no facade pixel.
    """
    r = np.asarray(rectified)
    if r.ndim != 3:
        raise ValueError(f"rectified labels must be (B, h, w), got {r.shape}")
    window, wall, door = ((r == c).sum(axis=(1, 2)) for c in
                          (SemanticClass.WINDOW, SemanticClass.WALL, SemanticClass.DOOR))
    return wwr_from_areas(window, wall, door)


def _rectangle_corners(sizes: np.ndarray) -> np.ndarray:
    """(B, 4, 2) corners (0,0), (w,0), (w,h), (0,h) of rectangles of (B, 2) sizes."""
    w, h = sizes[:, 0], sizes[:, 1]
    z = np.zeros_like(w)
    return np.stack([np.stack([z, z], -1), np.stack([w, z], -1),
                     np.stack([w, h], -1), np.stack([z, h], -1)], axis=1)
