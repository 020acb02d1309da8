"""A photo's z-depth from the sparse points it observes: measured at the points, piecewise
planar between them.

Structure from motion measures depth only where it triangulated a point: a few thousand
pixels of a photo. The 2D methods need depth on most of a facade's pixels (they fit planes
to depth normals, and a view whose depth covers under half of its building pixels is
refused: :data:`envelope.scenes.scene_validation.MAX_DEPTH_HOLE_FRACTION`), so the points
are joined into a surface that does not depend on any mask:

1. the points the photo observes (COLMAP's own 2D-3D correspondences, so no visibility
   test is needed: each was matched in this photo) are projected into it (pinhole, after
   undistortion), those in front of the camera and within an image's size of it kept;
2. their image positions are triangulated (Delaunay); each triangle is taken as the plane
   through its three points. Inverse depth is affine in the image over a plane, so the
   depth at a pixel centre is ``1 / (b . (1 / z))`` with ``b`` its barycentric coordinates:
   exact wherever a triangle's three points lie on one planar surface;
3. a triangle seen at more than ``max_incidence_deg`` from its normal is left out: it bridges
   a depth jump (a wall's edge and a far point behind it), not a surface. Pixels outside the
   points' hull, or in a left-out triangle, get no depth (0).

Measured: the depth at each point. Inferred: everything between, by the assumption that
the surface between neighbouring points is planar (it cuts a building's corners and
bridges small reliefs: balconies, reveals). See docs/importing.md, section 9.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from scipy.spatial import Delaunay, QhullError

from envelope.camera import Intrinsics, project_world_to_image

SUBPIXEL_BITS = 8
"""Corners are drawn to 1/256 px (OpenCV's ``shift``)."""


@dataclass(frozen=True)
class SparseDepthConfig:
    """How the points are joined (module docstring): a triangle whose plane is seen at
    more than ``max_incidence_deg`` from its normal is left out."""

    max_incidence_deg: float = 80.0

    def __post_init__(self) -> None:
        if not 0 < self.max_incidence_deg <= 90:
            raise ValueError(f"max_incidence_deg must be in (0, 90], got "
                             f"{self.max_incidence_deg}")


def piecewise_planar_depth_z_m(points_world_m: np.ndarray, intrinsics: Intrinsics,
                               world_from_camera: np.ndarray,
                               config: SparseDepthConfig = SparseDepthConfig()) -> np.ndarray:
    """(H, W) float64 z-depth (m; 0 = none) of the photo from the points it observes (module
    docstring).

    Parameters
    ----------
    points_world_m : (N, 3) float
        The points the photo observes, world frame (m).
    intrinsics : the photo's pinhole intrinsics (pixel centres at +0.5).
    world_from_camera : (4, 4) OpenGL camera-to-world pose.

    Raises
    ------
    ValueError
        ``points_world_m`` is not (N, 3) or not finite.
    """
    points = np.asarray(points_world_m, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 3 or not np.isfinite(points).all():
        raise ValueError(f"points_world_m must be finite (N, 3), got shape {points.shape}")
    depth = np.zeros((intrinsics.height, intrinsics.width))
    uv, z_m = project_world_to_image(points, intrinsics, world_from_camera)
    size = np.array([intrinsics.width, intrinsics.height])
    near = (z_m > 0) & np.all(np.abs(uv - size / 2) <= 1.5 * size, axis=1)
    uv, z_m = uv[near], z_m[near]  # in front, and projecting within an image's size of it
    if len(z_m) < 3:
        return depth
    try:
        triangles = Delaunay(uv)
    except QhullError:  # every point on one image line: no triangle
        return depth
    camera_xyz = _camera_points(uv, z_m, intrinsics)
    kept = np.flatnonzero(_facing(camera_xyz[triangles.simplices], config.max_incidence_deg))
    triangle_of_pixel = _rasterise(uv, triangles.simplices, kept, depth.shape)
    # A pixel near an edge was drawn with either triangle, or with one beside the hull: it
    # goes to the triangle holding its centre (-1: none), and is dropped unless that is kept.
    rows, cols = np.nonzero(_near_edges(uv, triangles.simplices[kept], depth.shape)
                            & (triangle_of_pixel >= 0))
    which = triangles.find_simplex(np.column_stack([cols + 0.5, rows + 0.5]))
    is_kept = np.zeros(len(triangles.simplices) + 1, bool)  # the last entry: index -1
    is_kept[kept] = True
    triangle_of_pixel[rows, cols] = np.where(is_kept[which], which, -1)
    gradient, offset = _inverse_depth_planes(triangles, 1.0 / z_m)
    rows, cols = np.nonzero(triangle_of_pixel >= 0)
    which = triangle_of_pixel[rows, cols]
    inverse_z = gradient[which, 0] * (cols + 0.5) + gradient[which, 1] * (rows + 0.5) \
        + offset[which]
    depth[rows, cols] = 1.0 / inverse_z
    return depth


def _inverse_depth_planes(triangles: Delaunay, inverse_z: np.ndarray
                          ) -> tuple[np.ndarray, np.ndarray]:
    """Each triangle's inverse depth as an affine function of the image point,
    ``gradient . (u, v) + offset``: (T, 2) and (T,), through its corners' (N,) ``inverse_z``."""
    affine = triangles.transform  # (T, 3, 2): barycentric from (u, v), third corner last
    w = inverse_z[triangles.simplices]  # (T, 3)
    gradient = np.einsum("tji,tj->ti", affine[:, :2], w[:, :2] - w[:, 2:])
    return gradient, w[:, 2] - np.einsum("ti,ti->t", gradient, affine[:, 2])


def _camera_points(uv: np.ndarray, z_m: np.ndarray, k: Intrinsics) -> np.ndarray:
    """(N, 3) OpenCV camera-frame points (x right, y down, z forward) of image points at
    z-depths."""
    return np.column_stack([(uv[:, 0] - k.cx) / k.fx * z_m, (uv[:, 1] - k.cy) / k.fy * z_m,
                            z_m])


def _facing(corners: np.ndarray, max_incidence_deg: float) -> np.ndarray:
    """(T,) bool: (T, 3, 3) camera-frame triangles seen within ``max_incidence_deg`` of
    their normal (at their centroid)."""
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    ray = corners.mean(axis=1)
    cos = np.abs(np.einsum("ti,ti->t", normal, ray)) / np.maximum(
        np.linalg.norm(normal, axis=1) * np.linalg.norm(ray, axis=1), 1e-300)
    return cos >= np.cos(np.radians(max_incidence_deg)) - 1e-12


def _near_edges(uv: np.ndarray, simplices: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """(H, W) bool: pixels within about two pixels of an edge of the (T, 3) triangles, where
    :func:`_rasterise` may have drawn a triangle beside the one holding the pixel's centre."""
    corners = np.round((uv - 0.5) * (1 << SUBPIXEL_BITS)).astype(np.int32)
    mask = np.zeros(shape, np.uint8)
    cv2.polylines(mask, list(corners[simplices]), True, 1, 1, cv2.LINE_8, SUBPIXEL_BITS)
    return cv2.dilate(mask, np.ones((3, 3), np.uint8)).astype(bool)


def _rasterise(uv: np.ndarray, simplices: np.ndarray, kept: np.ndarray,
               shape: tuple[int, int]) -> np.ndarray:
    """(H, W) int32: the index of the kept triangle covering each pixel, -1 for none.

    OpenCV fills a triangle's boundary pixels as well (pixel centres at integers there, so
    the corners are shifted by -0.5): a pixel on an edge shared by two triangles takes the
    one drawn last, and a pixel just outside the hull the triangle beside it (the caller
    sorts those out, :func:`_near_edges`).
    """
    corners = np.round((uv - 0.5) * (1 << SUBPIXEL_BITS)).astype(np.int32)
    out = np.full(shape, -1, np.int32)
    for t in kept:
        cv2.fillPoly(out, [corners[simplices[t]]], int(t), shift=SUBPIXEL_BITS)
    return out
