"""Facade planes found in labelled depth images, for data with no per-wall ground truth.

The BlenderProc layout (:mod:`dataset.importers.buildnet3d.blenderproc`) has no wall list, so its
facades come
from geometry: every wall pixel of every view is back-projected with its depth, its normal
is the cross product of its neighbours' points (turned towards the camera, so outward),
and near-vertical normals are grouped, first by azimuth (histogram peaks), then by the
plane offset along the peak's normal (gaps). Each group is one facade: an outward normal,
a centre and the bounding box of its points, the same wall records as the BuildNet3D-
dataset's ``wwr_information`` gives (:func:`dataset.buildnet3d.facade_ids_from_walls`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from envelope.camera import Intrinsics, pixel_centres, unproject_depth_to_world
from envelope.classes import SemanticClass


@dataclass(frozen=True)
class FacadeSearchConfig:
    """How facades are grouped.

    ``max_normal_z``: a point is on a wall if its normal's z is at most this (|n_z|).
    ``azimuth_window_deg``: points within this of a histogram peak belong to it.
    ``offset_gap_m``: parallel walls further apart than this along their normal are
    separate facades. ``min_share``: a facade holds at least this share of the points.
    ``max_points``: points kept (evenly sampled) for the search. ``trim``: share of points
    left out at each end of a facade's extent (stray pixels at corners).
    """

    max_normal_z: float = 0.3
    azimuth_window_deg: float = 20.0
    offset_gap_m: float = 0.5
    min_share: float = 0.02
    max_points: int = 200_000
    trim: float = 0.002


def facades_from_depth(views: list[tuple[np.ndarray, np.ndarray, Intrinsics, np.ndarray]],
                       config: FacadeSearchConfig = FacadeSearchConfig()
                       ) -> list[dict[str, Any]]:
    """Facade planes seen in ``views``, largest first.

    Parameters
    ----------
    views
        (labels (H, W) our class ids, depth_z_m (H, W) m with 0 = none, intrinsics,
        world_from_camera (4, 4) OpenGL) of each view.

    Returns
    -------
    One dict per facade: ``normal`` (3,) outward unit (horizontal), ``center`` (3,) m,
    ``domain`` (3, 2) min/max of x, y, z (m), ``points`` (how many points it holds).

    Raises
    ------
    ValueError
        No wall pixel with depth in any view.
    """
    points, normals = _wall_points_and_normals(views, config.max_normal_z)
    if len(points) == 0:
        raise ValueError("no wall pixel has a depth: facades cannot be found from geometry")
    if len(points) > config.max_points:
        keep = np.linspace(0, len(points) - 1, config.max_points).astype(int)
        points, normals = points[keep], normals[keep]
    azimuth = np.arctan2(normals[:, 1], normals[:, 0])
    left = np.ones(len(points), dtype=bool)
    min_points = max(20, int(config.min_share * len(points)))
    window = np.deg2rad(config.azimuth_window_deg)
    facades = []
    while left.sum() >= min_points:
        peak = _histogram_peak(azimuth[left])
        near = left & (np.abs(_wrap(azimuth - peak)) < window)
        if near.sum() < min_points:
            break
        peak = float(np.angle(np.exp(1j * azimuth[near]).mean()))
        normal = np.array([np.cos(peak), np.sin(peak), 0.0])
        offset = points @ normal
        for group in _split_at_gaps(np.flatnonzero(near), offset, config.offset_gap_m):
            if len(group) >= min_points:
                facades.append(_facade(points[group], normal, config.trim))
        left &= ~near
    return sorted(facades, key=lambda f: -f["points"])


def _wall_points_and_normals(views, max_normal_z: float) -> tuple[np.ndarray, np.ndarray]:
    """(N, 3) world points and (N, 3) outward unit normals of wall pixels."""
    all_points, all_normals = [], []
    for labels, depth, intr, pose in views:
        ok = (np.asarray(labels) == SemanticClass.WALL) & (np.asarray(depth) > 0)
        p = unproject_depth_to_world(pixel_centres(intr), np.asarray(depth, np.float64),
                                     intr, np.asarray(pose, np.float64))
        # A pixel's normal from its right and lower neighbours, all three on a wall.
        both = ok[:-1, :-1] & ok[:-1, 1:] & ok[1:, :-1]
        n = np.cross(p[:-1, 1:] - p[:-1, :-1], p[1:, :-1] - p[:-1, :-1])[both]
        q = p[:-1, :-1][both]
        length = np.linalg.norm(n, axis=1)
        good = length > 0
        n, q = n[good] / length[good, None], q[good]
        n[np.einsum("ij,ij->i", n, pose[:3, 3] - q) < 0] *= -1.0  # towards the camera
        all_points.append(q)
        all_normals.append(n)
    points, normals = np.concatenate(all_points), np.concatenate(all_normals)
    vertical = np.abs(normals[:, 2]) <= max_normal_z
    return points[vertical], normals[vertical]


def _histogram_peak(azimuth: np.ndarray, bins: int = 72) -> float:
    """Centre (rad) of the fullest bin of a circularly smoothed azimuth histogram."""
    counts, edges = np.histogram(azimuth, bins=bins, range=(-np.pi, np.pi))
    smooth = counts + 0.5 * (np.roll(counts, 1) + np.roll(counts, -1))
    i = int(np.argmax(smooth))
    return float(0.5 * (edges[i] + edges[i + 1]))


def _split_at_gaps(index: np.ndarray, offset: np.ndarray, gap: float) -> list[np.ndarray]:
    order = index[np.argsort(offset[index], kind="stable")]
    cuts = np.flatnonzero(np.diff(offset[order]) > gap) + 1
    return np.split(order, cuts)


def _facade(points: np.ndarray, normal: np.ndarray, trim: float) -> dict[str, Any]:
    lo = np.quantile(points, trim, axis=0)
    hi = np.quantile(points, 1.0 - trim, axis=0)
    offset = float(np.median(points @ normal))
    centre = 0.5 * (lo + hi)
    centre = centre + (offset - centre @ normal) * normal  # on the plane
    return {"normal": normal, "center": centre, "domain": np.stack([lo, hi], axis=1),
            "points": len(points)}


def _wrap(angle: np.ndarray) -> np.ndarray:
    return (angle + np.pi) % (2 * np.pi) - np.pi
