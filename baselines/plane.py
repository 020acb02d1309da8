"""Planes in the camera frame: back-projected depth pixels, RANSAC fit, ray intersection.

Everything here lives in the OpenGL camera frame (camera at the origin, looking
along -z, +y up), in metres. A pixel's ray is ``t * dir`` with ``dir`` from
:func:`envelope.camera.camera_dirs_from_pixels` (z = -1), so ``t`` is z-depth.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from envelope.camera import Intrinsics, camera_dirs_from_pixels


@dataclass(frozen=True)
class Plane:
    """The plane ``normal . x = offset_m`` in the camera frame.

    ``normal`` is a (3,) unit vector pointing towards the camera (the origin is
    on its positive side), so a positive :meth:`signed_distance_m` is in front
    of the plane and a negative one behind it (a recessed window).
    """

    normal: np.ndarray
    offset_m: float

    def signed_distance_m(self, points_m: np.ndarray) -> np.ndarray:
        """(...) signed distances (m) of (..., 3) points, positive towards the camera."""
        return np.asarray(points_m) @ self.normal - self.offset_m


def points_camera_m(uv: np.ndarray, depth_z_m: np.ndarray, intrinsics: Intrinsics) -> np.ndarray:
    """(..., 3) camera-frame points (m) of image points ``uv`` (..., 2) at z-depth (...)."""
    return camera_dirs_from_pixels(uv, intrinsics) * np.asarray(depth_z_m, np.float64)[..., None]


def plane_through_points(points_m: np.ndarray) -> Plane:
    """Least-squares (total) plane through (N, 3) points, N >= 3, oriented towards the camera.

    Raises
    ------
    ValueError
        If there are fewer than 3 points or they are (nearly) collinear.
    """
    p = np.asarray(points_m, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3 or len(p) < 3:
        raise ValueError(f"a plane needs at least 3 points of shape (N, 3), got {p.shape}")
    centroid = p.mean(axis=0)
    _, s, vt = np.linalg.svd(p - centroid, full_matrices=False)
    if s[1] <= 1e-9 * max(s[0], 1e-12):
        raise ValueError("the points are collinear; they do not define a plane")
    return _oriented(vt[2], float(vt[2] @ centroid))


def fit_plane_ransac(
    points_m: np.ndarray,
    *,
    threshold_m: float,
    iterations: int,
    rng: np.random.Generator,
    refine_points_m: np.ndarray | None = None,
    anchor_points_m: np.ndarray | None = None,
) -> Plane:
    """The plane with most inliers among ``points_m`` (N, 3), refined by least squares.

    Candidate planes come from random triples of ``points_m`` and are scored on
    them; the best is then refitted twice by least squares to its inliers among
    ``refine_points_m`` (M, 3) (default ``points_m``). With ``anchor_points_m``
    (A, 3), every candidate passes through one of them: the plane sought is the
    best-supported one through the anchors, not the best-supported overall.

    Raises
    ------
    ValueError
        If fewer than 3 points are given or no candidate has 3 inliers.
    """
    p = np.asarray(points_m, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3 or len(p) < 3:
        raise ValueError(f"RANSAC needs at least 3 points of shape (N, 3), got {p.shape}")
    if threshold_m <= 0 or iterations < 1:
        raise ValueError("threshold_m must be > 0 and iterations >= 1")
    idx = rng.integers(0, len(p), (iterations, 3))  # repeated indices give a zero normal
    a, b, c = p[idx[:, 0]], p[idx[:, 1]], p[idx[:, 2]]
    if anchor_points_m is not None:
        anchors = np.asarray(anchor_points_m, dtype=np.float64).reshape(-1, 3)
        if len(anchors) == 0:
            raise ValueError("anchor_points_m is empty")
        a = anchors[rng.integers(0, len(anchors), iterations)]
    normals = np.cross(b - a, c - a)
    norms = np.linalg.norm(normals, axis=1)
    ok = norms > 1e-12
    if not ok.any():
        raise ValueError("every RANSAC sample was degenerate (collinear points)")
    normals = normals[ok] / norms[ok, None]
    offsets = np.einsum("ij,ij->i", normals, a[ok])
    inliers = np.abs(p @ normals.T - offsets) <= threshold_m  # (N, K)
    best = int(np.argmax(inliers.sum(axis=0)))
    plane = _oriented(normals[best], float(offsets[best]))
    refine = p if refine_points_m is None else np.asarray(refine_points_m, dtype=np.float64)
    for _ in range(2):
        sel = np.abs(plane.signed_distance_m(refine)) <= threshold_m
        if sel.sum() < 3:
            raise ValueError("the best RANSAC plane has fewer than 3 inliers")
        plane = plane_through_points(refine[sel])
    return plane


def intersect_rays_plane(uv: np.ndarray, plane: Plane, intrinsics: Intrinsics) -> np.ndarray:
    """(..., 3) camera-frame points (m) where the rays through ``uv`` (..., 2) meet ``plane``.

    Raises
    ------
    ValueError
        If a ray is parallel to the plane or meets it behind the camera.
    """
    dirs = camera_dirs_from_pixels(uv, intrinsics)
    denom = dirs @ plane.normal
    with np.errstate(divide="ignore", invalid="ignore"):
        t = plane.offset_m / denom
    if not np.all(np.isfinite(t)) or np.any(t <= 0):
        raise ValueError("a ray through the facade corners misses the facade plane "
                         "(plane seen edge-on or behind the camera)")
    return dirs * t[..., None]


def _oriented(normal: np.ndarray, offset_m: float) -> Plane:
    # The camera (origin) must be on the positive side: 0 - offset > 0.
    if offset_m > 0:
        return Plane(-normal, -offset_m)
    return Plane(np.asarray(normal, dtype=np.float64), offset_m)
