"""Vertical facade planes in one posed view, fitted to its depth (world frame, metres).

Every wall, window and door pixel with depth is put in the world frame
(:meth:`baselines.posed_views.PosedView.world_points_m`); its surface normal is the cross
product of its neighbours' differences (right and down in the image). Pixels whose normal
is within ``max_tilt_deg`` of horizontal may lie on a facade. Facades are vertical, so a
plane is a line in the ground plane x-y: sequential one-point RANSAC draws a pixel, takes the
vertical plane through it with its normal, counts the pixels within ``threshold_m`` of it
whose normal agrees within ``normal_agreement_deg``, keeps the best, refits it by least
squares to its inliers (twice), removes them and starts again. The inliers of one plane are
cut where they leave a gap wider than ``gap_m`` along it: each run of them with at least
``min_points`` pixels spanning at least ``min_width_m`` is one :class:`ViewPlane` (two
coplanar walls apart are two facades; a run narrower than that is the crease of a corner,
whose pixels' normals blend both walls').
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from baselines.posed_views import PosedView

UP = np.array([0.0, 0.0, 1.0])


@dataclass(frozen=True)
class PlaneFitConfig:
    """How planes are found in one view (module docstring); chosen on the tiny preset."""

    threshold_m: float = 0.15
    normal_agreement_deg: float = 20.0
    max_tilt_deg: float = 15.0
    gap_m: float = 1.0
    min_width_m: float = 0.5
    min_points: int = 50
    hypotheses: int = 64
    max_planes: int = 8
    max_points: int = 20000

    def __post_init__(self) -> None:
        if not (self.threshold_m > 0 and self.gap_m > 0 and self.min_width_m >= 0):
            raise ValueError("threshold_m and gap_m must be > 0 and min_width_m >= 0")
        if not (0 < self.normal_agreement_deg < 90 and 0 < self.max_tilt_deg < 90):
            raise ValueError("normal_agreement_deg and max_tilt_deg must be in (0, 90)")
        if min(self.min_points, self.hypotheses, self.max_planes, self.max_points) < 1:
            raise ValueError("min_points, hypotheses, max_planes and max_points must be >= 1")


@dataclass(frozen=True)
class ViewPlane:
    """A vertical plane seen in one view: ``normal . x = offset_m`` (world frame).

    ``normal`` (3,) horizontal unit vector pointing to the view's camera; :attr:`along` (3,)
    the plane's horizontal direction, ``up x normal`` (rightwards seen from outside);
    ``s_range_m`` and ``z_range_m`` the extent of its inliers along ``along`` and in height;
    ``points_m`` (P, 3) its inliers (a subsample), ``n_points`` how many there were.
    """

    view_index: int
    normal: np.ndarray
    offset_m: float
    s_range_m: tuple[float, float]
    z_range_m: tuple[float, float]
    points_m: np.ndarray
    n_points: int

    @property
    def along(self) -> np.ndarray:
        return np.cross(UP, self.normal)


def pixel_normals(points_m: np.ndarray, valid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit normals (H, W, 3) of (H, W, 3) world points from their image neighbours, and
    (H, W) bool where defined (the pixel and its right and lower neighbours ``valid``)."""
    p = np.asarray(points_m, dtype=np.float64)
    right = np.zeros_like(p)
    down = np.zeros_like(p)
    right[:, :-1] = p[:, 1:] - p[:, :-1]
    down[:-1] = p[1:] - p[:-1]
    ok = valid.copy()
    ok[:, -1] = False
    ok[-1] = False
    ok[:, :-1] &= valid[:, 1:]
    ok[:-1] &= valid[1:]
    n = np.cross(down, right)
    norm = np.linalg.norm(n, axis=-1)
    ok &= norm > 1e-12
    n[ok] /= norm[ok, None]
    return n, ok


def find_view_planes(view: PosedView, config: PlaneFitConfig,
                     rng: np.random.Generator) -> list[ViewPlane]:
    """The vertical facade planes of one view (module docstring), largest first; empty when
    the view shows no wall with enough pixels."""
    points = view.world_points_m()
    normals, ok = pixel_normals(points, view.facade_pixels())
    ok &= np.abs(normals[..., 2]) <= np.sin(np.radians(config.max_tilt_deg))
    p, n = points[ok], normals[ok]
    if len(p) > config.max_points:
        keep = rng.choice(len(p), config.max_points, replace=False)
        p, n = p[keep], n[keep]
    n = n.copy()
    n[:, 2] = 0.0
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    camera = view.camera_m
    n *= np.sign(np.einsum("ij,ij->i", camera - p, n))[:, None]  # towards the camera
    cos_agree = np.cos(np.radians(config.normal_agreement_deg))
    planes: list[ViewPlane] = []
    remaining = np.ones(len(p), dtype=bool)
    for _ in range(config.max_planes):
        idx = np.flatnonzero(remaining)
        if len(idx) < config.min_points:
            break
        seeds = rng.choice(idx, min(config.hypotheses, len(idx)), replace=False)
        hn = n[seeds]  # (K, 3)
        ho = np.einsum("ij,ij->i", hn, p[seeds])
        inl = (np.abs(p[idx] @ hn.T - ho) <= config.threshold_m) & (n[idx] @ hn.T >= cos_agree)
        best = int(np.argmax(inl.sum(axis=0)))
        normal, offset = hn[best], float(ho[best])
        for _ in range(2):
            sel = idx[(np.abs(p[idx] @ normal - offset) <= config.threshold_m)
                      & (n[idx] @ normal >= cos_agree)]
            if len(sel) < config.min_points:
                break
            normal, offset = _vertical_plane_through(p[sel], camera)
        sel = idx[(np.abs(p[idx] @ normal - offset) <= config.threshold_m)
                  & (n[idx] @ normal >= cos_agree)]
        if len(sel) < config.min_points:
            break
        remaining[sel] = False
        planes += _runs_along(view.index, normal, offset, p[sel], config, rng)
    return sorted(planes, key=lambda q: -q.n_points)


def _vertical_plane_through(points_m: np.ndarray, camera_m: np.ndarray) -> tuple[np.ndarray,
                                                                                   float]:
    """Least-squares vertical plane (normal towards ``camera_m``, offset) through (N, 3)
    points: the line through their x-y by total least squares."""
    xy = points_m[:, :2]
    centre = xy.mean(axis=0)
    _, _, vt = np.linalg.svd(xy - centre, full_matrices=False)
    normal = np.array([vt[1, 0], vt[1, 1], 0.0])
    if normal[:2] @ (camera_m[:2] - centre) < 0:
        normal = -normal
    return normal, float(normal[:2] @ centre)


def _runs_along(view_index: int, normal: np.ndarray, offset_m: float, points_m: np.ndarray,
                config: PlaneFitConfig, rng: np.random.Generator) -> list[ViewPlane]:
    """The plane's inliers cut at gaps wider than ``gap_m`` along it: one plane per run."""
    along = np.cross(UP, normal)
    s = points_m @ along
    order = np.argsort(s)
    cuts = np.flatnonzero(np.diff(s[order]) > config.gap_m) + 1
    out = []
    for run in np.split(order, cuts):
        if len(run) < config.min_points or np.ptp(s[run]) < config.min_width_m:
            continue
        pts = points_m[run]
        sample = pts if len(pts) <= 500 else pts[rng.choice(len(pts), 500, replace=False)]
        out.append(ViewPlane(view_index, normal, offset_m,
                             (float(s[run].min()), float(s[run].max())),
                             (float(pts[:, 2].min()), float(pts[:, 2].max())), sample, len(run)))
    return out
