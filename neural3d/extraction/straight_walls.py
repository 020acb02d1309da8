"""Straight walls: the runs of a footprint that follow a line, replaced by that line.

The zero contour of a trained SDF wobbles about a straight wall by a fraction of
a pixel and rounds the wall's corners (the field is smooth at the scale of a
few grid cells). The contour is cut into runs: the edges of its Douglas-Peucker
simplification at ``tolerance_m``, started at its sharpest corner (a start in
the middle of a wall would cut the wall in two). A run at least ``min_wall_m``
long end to end is a wall and becomes the total-least-squares line of its
points, the ends of the run left out of the fit (``END_TRIM`` of its points at
each end, where a rounded corner bends away). Two neighbouring walls meet where
their lines cross (a sharp corner) when they turn by at least ``MIN_CORNER_DEG``
and the crossing lies within ``min_wall_m`` / 2 of the contour's corner;
otherwise each ends at its projection of that corner. A shorter run (a curve, a
small jog) keeps its points, its ends moved onto the neighbouring walls' lines.

What it assumes, and where it biases: a run the simplification keeps within
``tolerance_m`` of a line for ``min_wall_m`` is a straight wall, so a curved wall
becomes a polygon whose sides stray up to about ``tolerance_m`` from it (a
circle of radius 5 m keeps an IoU above 0.99 with itself); a corner the field
rounds by more than ``tolerance_m`` (a radius above about 0.36 m) keeps part of
its rounding as a short run. A piece (a polygon with its holes) whose
straightened form is not a valid polygon keeps its points.
"""

from __future__ import annotations

import numpy as np
from shapely.geometry import MultiPolygon, Polygon

END_TRIM = 0.15  # fraction of a run left out of its line fit at each end
MIN_CORNER_DEG = 20.0  # two walls turning by less keep a short jog between them


def straighten_footprint(polygon: Polygon | MultiPolygon, *, tolerance_m: float,
                         min_wall_m: float) -> Polygon | MultiPolygon:
    """``polygon`` (world x/y m) with each ring's straight runs replaced by their lines.

    Raises
    ------
    ValueError
        If ``tolerance_m`` or ``min_wall_m`` is not positive.
    """
    if not tolerance_m > 0 or not min_wall_m > 0:
        raise ValueError(f"tolerance_m and min_wall_m must be > 0, got {tolerance_m}, "
                         f"{min_wall_m}")
    pieces = []
    for piece in getattr(polygon, "geoms", [polygon]):
        exterior = _straight_ring(np.asarray(piece.exterior.coords)[:-1], tolerance_m,
                                  min_wall_m)
        holes = [_straight_ring(np.asarray(h.coords)[:-1], tolerance_m, min_wall_m)
                 for h in piece.interiors]
        straight = Polygon(exterior, holes)
        pieces.append(straight if straight.is_valid and not straight.is_empty else piece)
    return pieces[0] if len(pieces) == 1 else MultiPolygon(pieces)


def douglas_peucker_indices(points_m: np.ndarray, tolerance_m: float) -> np.ndarray:
    """Indices of the points that the Douglas-Peucker simplification of an open chain keeps.

    ``points_m``: "(N, 2)"; the first and last points are always kept. Returns sorted
    "(K,)" int indices.
    """
    keep = np.zeros(len(points_m), dtype=bool)
    keep[[0, -1]] = True
    stack = [(0, len(points_m) - 1)]
    while stack:
        i, j = stack.pop()
        if j - i < 2:
            continue
        distance = _distance_to_chord(points_m[i + 1:j], points_m[i], points_m[j])
        k = int(np.argmax(distance))
        if distance[k] > tolerance_m:
            keep[i + 1 + k] = True
            stack += [(i, i + 1 + k), (i + 1 + k, j)]
    return np.flatnonzero(keep)


def _straight_ring(ring_m: np.ndarray, tolerance_m: float, min_wall_m: float) -> np.ndarray:
    """A closed ring "(N, 2)" (last point not repeated) with its straight runs straightened."""
    if len(ring_m) < 4:
        return ring_m
    corners = _ring_corners(ring_m, tolerance_m)
    ring_m = np.roll(ring_m, -int(corners[np.argmax(_turns_deg(ring_m[corners]))]), axis=0)
    corners = _ring_corners(ring_m, tolerance_m)
    if len(corners) < 3:
        return ring_m
    closed = np.vstack([ring_m, ring_m[:1]])
    ends = np.append(corners[1:], len(ring_m))  # run k covers points corners[k] .. ends[k]
    lines = [_wall_line(closed[a:b + 1], min_wall_m) for a, b in zip(corners, ends)]
    out: list[np.ndarray] = []
    for k in range(len(corners)):
        out += _corner_points(closed[corners[k]], lines[k - 1], lines[k], min_wall_m)
        if lines[k] is None:  # a short run keeps its own points
            out += list(closed[corners[k] + 1:ends[k]])
    return np.asarray(out)


def _ring_corners(ring_m: np.ndarray, tolerance_m: float) -> np.ndarray:
    """Douglas-Peucker vertices of a closed ring, as indices into it (the first is 0)."""
    closed = np.vstack([ring_m, ring_m[:1]])
    return douglas_peucker_indices(closed, tolerance_m)[:-1]


def _turns_deg(vertices_m: np.ndarray) -> np.ndarray:
    """Turning angle (degrees, 0-180) of a closed polygon at each of its vertices "(K, 2)"."""
    into = vertices_m - np.roll(vertices_m, 1, axis=0)
    out = np.roll(vertices_m, -1, axis=0) - vertices_m
    cos = (into * out).sum(1) / np.maximum(
        np.linalg.norm(into, axis=1) * np.linalg.norm(out, axis=1), 1e-12)
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


def _wall_line(run_m: np.ndarray, min_wall_m: float) -> tuple[np.ndarray, np.ndarray] | None:
    """(point, unit direction) of the line through a run "(M, 2)", or None if it is shorter
    than ``min_wall_m``. The run's ends (``END_TRIM`` of its points each) are left out."""
    if np.linalg.norm(run_m[-1] - run_m[0]) < min_wall_m:
        return None
    trim = int(END_TRIM * len(run_m))
    core = run_m[trim:len(run_m) - trim] if len(run_m) - 2 * trim >= 2 else run_m
    centre = core.mean(axis=0)
    direction = np.linalg.svd(core - centre, full_matrices=False)[2][0]
    return centre, direction


def _corner_points(corner_m: np.ndarray, before, after, min_wall_m: float) -> list[np.ndarray]:
    """The ring's point(s) at a contour corner between the runs ``before`` and ``after``
    (each a wall's line, or None for a short run)."""
    if before is None and after is None:
        return [corner_m]
    if before is None or after is None:
        return [_project(corner_m, after if before is None else before)]
    (p0, d0), (p1, d1) = before, after
    cross = d0[0] * d1[1] - d0[1] * d1[0]
    if abs(cross) >= np.sin(np.radians(MIN_CORNER_DEG)):
        meet = p0 + ((p1 - p0)[0] * d1[1] - (p1 - p0)[1] * d1[0]) / cross * d0
        if np.linalg.norm(meet - corner_m) <= min_wall_m / 2:
            return [meet]
    return [_project(corner_m, before), _project(corner_m, after)]


def _project(point_m: np.ndarray, line) -> np.ndarray:
    centre, direction = line
    return centre + np.dot(point_m - centre, direction) * direction


def _distance_to_chord(points_m: np.ndarray, a_m: np.ndarray, b_m: np.ndarray) -> np.ndarray:
    chord = b_m - a_m
    length = np.linalg.norm(chord)
    if length < 1e-12:
        return np.linalg.norm(points_m - a_m, axis=1)
    rel = points_m - a_m
    return np.abs(rel[:, 0] * chord[1] - rel[:, 1] * chord[0]) / length
