"""Facade corners in 3D and the facade's length and height (2D-SS).

A corner often sits exactly on the facade's edge, where its own depth pixel may
be background or a neighbouring surface, so corners are never read from the
depth image: each corner's ray is intersected with the plane fitted to the
facade's depth pixels (:mod:`baselines.facade_mask`).
"""

from __future__ import annotations

import numpy as np

from baselines.plane import Plane, intersect_rays_plane
from baselines.views import ViewError
from dataset.camera import Intrinsics


def corners_camera_m(corners_uv: np.ndarray, plane: Plane, intrinsics: Intrinsics) -> np.ndarray:
    """(4, 3) camera-frame corner points (m) of (4, 2) image corners on ``plane``.

    Raises
    ------
    ViewError
        If a corner's ray misses the plane (plane seen edge-on).
    """
    c = np.asarray(corners_uv, dtype=np.float64)
    if c.shape != (4, 2):
        raise ValueError(f"corners must be (4, 2) image points, got {c.shape}")
    try:
        return intersect_rays_plane(c, plane, intrinsics)
    except ValueError as exc:
        raise ViewError(str(exc)) from exc


def facade_size_m(corners_m: np.ndarray) -> tuple[float, float]:
    """Facade length L and height H (m) of a 3D quadrilateral.

    Parameters
    ----------
    corners_m : (4, 3) float
        Corners in the order top-left, top-right, bottom-right, bottom-left (any
        frame; lengths do not depend on it).

    Returns
    -------
    length_m : mean of the top and bottom edge lengths
    height_m : mean of the left and right edge lengths
    """
    c = np.asarray(corners_m, dtype=np.float64)
    if c.shape != (4, 3):
        raise ValueError(f"corners must be (4, 3) points, got {c.shape}")
    tl, tr, br, bl = c
    length = 0.5 * (np.linalg.norm(tr - tl) + np.linalg.norm(br - bl))
    height = 0.5 * (np.linalg.norm(bl - tl) + np.linalg.norm(br - tr))
    if length <= 0 or height <= 0:
        raise ViewError("the facade quadrilateral is degenerate (zero length or height)")
    return float(length), float(height)
