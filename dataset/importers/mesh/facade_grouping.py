"""Group the wall, window and door faces of a building into facades.

A facade is a set of near-vertical faces that (1) face the same horizontal direction,
(2) lie in the same plane offset along it and (3) form one contiguous stretch along the
wall. So the two +x walls of an L-shaped building are two facades (different offsets),
as are two coplanar wings with a gap between them. Directions are clustered greedily,
largest faces first: a curved wall is cut into sectors at most
``2 * angle_tolerance_deg`` wide, each its own (curved) facade.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from envelope.classes import NO_FACADE


@dataclass(frozen=True)
class FacadeGroup:
    """One facade found by :func:`group_facades`.

    ``normal`` is the area-weighted mean outward horizontal unit normal; ``offset_m``
    the plane's distance from the origin along it; ``along_m`` the (min, max) extent
    along the wall direction ``(-n_y, n_x, 0)``; ``face_index`` the member faces.
    """

    normal: tuple[float, float, float]
    offset_m: float
    along_m: tuple[float, float]
    face_index: np.ndarray


def group_facades(
    triangles_m: np.ndarray,
    normals: np.ndarray,
    areas_m2: np.ndarray,
    candidate: np.ndarray,
    *,
    max_tilt_deg: float,
    angle_tolerance_deg: float,
    offset_tolerance_m: float,
    gap_tolerance_m: float,
    min_width_m: float,
) -> list[FacadeGroup]:
    """Facades among the ``candidate`` faces, in a deterministic order.

    Parameters
    ----------
    triangles_m : (F, 3, 3) float
    normals : (F, 3) float
        Outward unit normals.
    areas_m2 : (F,) float
    candidate : (F,) bool
        Faces that may belong to a facade (visible wall, window and door faces).
    max_tilt_deg
        Faces whose normal is further than this from horizontal are no facade.
    angle_tolerance_deg
        Faces within this angle of a facade's direction join it.
    offset_tolerance_m
        Parallel planes whose offsets differ by less (chained) are one facade, so that
        windows set back into the wall stay on their facade.
    gap_tolerance_m
        Coplanar pieces further apart than this along the wall are different facades.
    min_width_m
        Groups narrower than this along the wall (window reveals, pilaster sides) are no facade.

    Returns
    -------
    list of FacadeGroup, ordered by azimuth of the normal (counter-clockwise from +x),
    then offset, then position along the wall; facade id = list index + 1.
    """
    tri = np.asarray(triangles_m, dtype=np.float64)
    n = np.asarray(normals, dtype=np.float64)
    areas = np.asarray(areas_m2, dtype=np.float64)
    horizontal = np.linalg.norm(n[:, :2], axis=1)
    upright = np.asarray(candidate, dtype=bool) & (
        np.abs(n[:, 2]) <= np.sin(np.deg2rad(max_tilt_deg))
    ) & (areas > 0)
    index = np.flatnonzero(upright)
    if len(index) == 0:
        return []
    h = n[index, :2] / horizontal[index, None]
    groups: list[FacadeGroup] = []
    for members, direction in _direction_clusters(h, areas[index], angle_tolerance_deg):
        faces = index[members]
        centroid_offset = tri[faces].mean(axis=1)[:, :2] @ direction
        for offset_members in _split_sorted(centroid_offset, offset_tolerance_m):
            plane_faces = faces[offset_members]
            tangent = np.array([-direction[1], direction[0]])
            along = tri[plane_faces][:, :, :2] @ tangent  # (f, 3)
            for piece in _split_intervals(along.min(axis=1), along.max(axis=1), gap_tolerance_m):
                piece_faces = plane_faces[piece]
                lo, hi = float(along[piece].min()), float(along[piece].max())
                if hi - lo < min_width_m:
                    continue
                w = areas[piece_faces]
                offset = float(np.sum(w * centroid_offset[offset_members][piece]) / w.sum())
                groups.append(FacadeGroup(
                    normal=(float(direction[0]), float(direction[1]), 0.0),
                    offset_m=offset,
                    along_m=(lo, hi),
                    face_index=np.sort(piece_faces),
                ))
    groups.sort(key=lambda g: (
        round(np.degrees(np.arctan2(g.normal[1], g.normal[0])) % 360.0, 6),
        round(g.offset_m, 6),
        round(g.along_m[0], 6),
    ))
    return groups


def facade_ids_of_faces(groups: list[FacadeGroup], n_faces: int) -> np.ndarray:
    """(n_faces,) int32 facade id per face (group index + 1), :data:`NO_FACADE` elsewhere."""
    ids = np.full(n_faces, NO_FACADE, dtype=np.int32)
    for i, g in enumerate(groups):
        ids[g.face_index] = i + 1
    return ids


def _direction_clusters(
    h: np.ndarray, areas: np.ndarray, angle_tolerance_deg: float
) -> list[tuple[np.ndarray, np.ndarray]]:
    """Greedy clusters of (N, 2) unit directions: (member indices, mean unit direction)."""
    cos_tol = np.cos(np.deg2rad(angle_tolerance_deg))
    free = np.ones(len(h), dtype=bool)
    clusters = []
    while free.any():
        seed = np.flatnonzero(free)[np.argmax(areas[free])]
        direction = h[seed]
        # Re-centre once on the members' mean so that the seed's own tilt does not decide.
        for _ in range(2):
            members = np.flatnonzero(free & (h @ direction >= cos_tol))
            mean = (areas[members, None] * h[members]).sum(axis=0)
            direction = mean / np.linalg.norm(mean)
        members = np.flatnonzero(free & (h @ direction >= cos_tol))
        if len(members) == 0:  # the mean drifted off every free face: take the seed alone
            members, direction = np.array([seed]), h[seed]
        free[members] = False
        clusters.append((members, direction))
    return clusters


def _split_sorted(values: np.ndarray, tolerance: float) -> list[np.ndarray]:
    """Index sets of ``values`` split where sorted neighbours differ by more than ``tolerance``."""
    order = np.argsort(values, kind="stable")
    breaks = np.flatnonzero(np.diff(values[order]) > tolerance) + 1
    return np.split(order, breaks)


def _split_intervals(lo: np.ndarray, hi: np.ndarray, gap: float) -> list[np.ndarray]:
    """Index sets of intervals [lo, hi] joined where they overlap or lie within ``gap``."""
    order = np.argsort(lo, kind="stable")
    reach = np.maximum.accumulate(hi[order])
    breaks = np.flatnonzero(lo[order][1:] > reach[:-1] + gap) + 1
    return np.split(order, breaks)
