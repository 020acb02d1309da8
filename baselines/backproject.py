"""Facade corners in 3D and the facade's length and height (2D-SS).

A corner often sits exactly on the facade's edge, where its own depth pixel may
be background or a neighbouring surface, so corners are never read from the
depth image: each corner's ray is intersected with the plane fitted to the
facade's depth pixels (:mod:`baselines.facade_mask`).

When the enclosing quadrilateral is not a rectangle in 3D (a gable facade is a
pentagon; an occluder can bite a corner off), :func:`upright_rectangle_m`
gives the facade's bounding rectangle in its plane instead, with vertical sides
along gravity (known from the camera pose). The facade's own area, for a facade
that is no rectangle, is its mask's outline put on the plane
(:func:`outline_area_on_plane_m2`).
"""

from __future__ import annotations

import numpy as np

from baselines.plane import Plane, intersect_rays_plane
from baselines.views import ViewError
from envelope.camera import Intrinsics, project_world_to_image


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
    return points_on_plane_m(c, plane, intrinsics)


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


def corner_angles_deg(corners_m: np.ndarray) -> np.ndarray:
    """(4,) interior angles (degrees) of a (4, 3) quadrilateral, in corner order."""
    c = np.asarray(corners_m, dtype=np.float64)
    if c.shape != (4, 3):
        raise ValueError(f"corners must be (4, 3) points, got {c.shape}")
    a = np.roll(c, 1, axis=0) - c
    b = np.roll(c, -1, axis=0) - c
    cos = np.einsum("ij,ij->i", a, b) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


def upright_rectangle_m(contour_uv: np.ndarray, plane: Plane, intrinsics: Intrinsics,
                        up_camera: np.ndarray) -> np.ndarray:
    """(4, 3) bounding rectangle (TL, TR, BR, BL) of a facade outline in its plane, camera frame.

    Each boundary pixel's four pixel corners are put on the plane; the rectangle
    has its sides along the plane's horizontal and along gravity projected into
    the plane, and encloses them all.

    Parameters
    ----------
    contour_uv : (N, 2) float
        Centres of the facade's boundary pixels.
    up_camera : (3,) float
        World up (+z) in the camera frame: ``world_from_camera[:3, :3].T @ (0, 0, 1)``.

    Raises
    ------
    ViewError
        If the plane is (nearly) horizontal or a ray misses it.
    """
    n = plane.normal
    up = np.asarray(up_camera, dtype=np.float64)
    vertical = up - (up @ n) * n
    if np.linalg.norm(vertical) < 0.1:
        raise ViewError("the facade plane is nearly horizontal; it has no upright rectangle")
    vertical /= np.linalg.norm(vertical)
    right = np.cross(vertical, n)  # n points to the camera: this is the camera's right
    offsets = np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])
    uv = (np.asarray(contour_uv, dtype=np.float64)[:, None, :] + offsets).reshape(-1, 2)
    pts = points_on_plane_m(uv, plane, intrinsics)
    s, z = pts @ right, pts @ vertical
    origin = (pts[0] @ n) * n  # the plane's point nearest the camera centre
    s0, s1, z0, z1 = s.min(), s.max(), z.min(), z.max()
    corners = [(s0, z1), (s1, z1), (s1, z0), (s0, z0)]
    return np.array([origin + a * right + b * vertical for a, b in corners])


def points_on_plane_m(uv: np.ndarray, plane: Plane, intrinsics: Intrinsics) -> np.ndarray:
    """(N, 3) points where the rays through (N, 2) image points meet ``plane``; ViewError if not."""
    try:
        return intersect_rays_plane(uv, plane, intrinsics)
    except ValueError as exc:
        raise ViewError(str(exc)) from exc


def image_from_camera_uv(points_m: np.ndarray, intrinsics: Intrinsics) -> np.ndarray:
    """(..., 2) image points of (..., 3) camera-frame points (OpenGL frame, in front)."""
    uv, _ = project_world_to_image(points_m, intrinsics, np.eye(4))
    return uv


def outline_area_on_plane_m2(mask: np.ndarray, plane: Plane, intrinsics: Intrinsics) -> float:
    """Area (m²) on ``plane`` of the region inside a facade mask's outline.

    Each image column of the mask is filled from its top facade pixel to its bottom one
    (windows set back from the plane, balcony bands and other occluders across the facade
    do not count as gaps; a gable's or a step's top edge does); every pixel of the filled
    region is put on the plane by its four corners, and the quadrilaterals' areas are
    summed (half the cross product of their diagonals).

    Parameters
    ----------
    mask : (H, W) bool
        The facade's pixels.

    Raises
    ------
    ViewError
        If the mask is empty or a pixel corner's ray misses the plane.
    """
    m = np.asarray(mask, dtype=bool)
    below_top = np.maximum.accumulate(m, axis=0)
    above_bottom = np.maximum.accumulate(m[::-1], axis=0)[::-1]
    filled = below_top & above_bottom
    rows, cols = np.nonzero(filled)
    if len(rows) == 0:
        raise ViewError("the facade mask is empty")
    r0, c0 = rows.min(), cols.min()
    sub = filled[r0:rows.max() + 1, c0:cols.max() + 1]
    h, w = sub.shape
    # Pixel (r, c) spans [c, c + 1] x [r, r + 1] in continuous image coordinates.
    v, u = np.meshgrid(np.arange(h + 1.0) + r0, np.arange(w + 1.0) + c0, indexing="ij")
    corners = points_on_plane_m(np.stack([u.ravel(), v.ravel()], axis=1), plane, intrinsics)
    corners = corners.reshape(h + 1, w + 1, 3)
    d1 = corners[1:, 1:] - corners[:-1, :-1]
    d2 = corners[1:, :-1] - corners[:-1, 1:]
    area = 0.5 * np.linalg.norm(np.cross(d1, d2), axis=-1)
    return float(area[sub].sum())
