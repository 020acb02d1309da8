"""Facade hidden in a concave corner: each wall continues to where the two walls meet.

A trained field fills the concave corner between two walls (the inner corner
of an L) with a fillet or chamfer: colour and labels look the same from every
camera whether the corner is sharp or filled, so nothing in the images undoes
it. The fillet's triangles lie more than ``plane_slab_m`` in front of either
wall's plane and face neither squarely, so neither wall counts them, and the
probes of :mod:`neural3d.extraction.occluded_facade` start inside the fillet
and see nothing there: each inner wall loses a strip as wide as the fillet
over its whole height.

Two facade planes A and B of :class:`neural3d.extraction.facade_planes.FacadePlanes`
form a concave corner when their normals are between 45 and 135 degrees apart
and the facade that each counts lies, on average, in front of the other's
plane (at a convex corner it lies behind). Their corner line is the vertical
line where the planes meet. On each row (fixed z) of A's probe grid, the cells
from A's known cell nearest the corner (seen or filled, its class) to the
corner line are filled with that cell's class when the run is at most
``max_gap_m`` long and, in each of its cells, a ray from ``reach_m`` in front
of A meets, in front of A's plane and within ``max_gap_m`` of it, a surface:
the fillet. The run's cells are filled, and the faces in front of them (their
centres within ``max_gap_m`` in front of A, over the run's cells) no longer
count on A (their shadow on A, or, near no plane, their own area): the strip
replaces them. A row whose run meets no surface in some cell (the corner is
open there) gets nothing. Where A took a row, its faces within
``curve_strip_m`` of the fillet count their shadow on A, as at a convex corner:
the part of the fillet near A's plane would otherwise tilt the mean normal of
A's last strip and inflate that strip as if the wall curved there
(:func:`neural3d.extraction.facade_planes.project_onto_facade_planes`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from envelope.classes import NUM_CLASSES
from envelope.geometry.raycast import Raycaster
from envelope.mesh import triangle_areas_m2, triangle_normals
from neural3d.extraction.facade_planes import FacadePlanes, plane_frame
from neural3d.extraction.occluded_facade import PlaneProbe

CORNER_ANGLES_DEG = (45.0, 135.0)  # normals this far apart can meet in a corner


@dataclass(frozen=True)
class CornerFill:
    """What concave corners change: ``area_m2`` (K, NUM_CLASSES) added on each plane, by
    class; ``planes`` the facade planes with the fillets' faces no longer counted (on a
    plane, or near none) and each filled wall's last strip counted as its shadow."""

    area_m2: np.ndarray
    planes: FacadePlanes


def concave_corner_fill(
    raycaster: Raycaster, planes: FacadePlanes, probes: list[PlaneProbe | None],
    labels: list[np.ndarray | None], *, cell_m: float, reach_m: float, max_gap_m: float,
    strip_m: float,
) -> CornerFill:
    """Facade area on each plane between its end and a concave corner (module docstring).

    Parameters
    ----------
    raycaster : over the measured mesh (world metres)
    planes : the mesh's facade planes (``weight`` (F, K): the faces each plane counts)
    probes, labels : each plane's probe grid and (U, Z) known classes (-1 unknown), from
        :func:`neural3d.extraction.occluded_facade.probe_planes` and
        :func:`~neural3d.extraction.occluded_facade.seen_cell_labels` (or, with the
        occluded fill, :func:`~neural3d.extraction.occluded_facade.occluded_facade_labels`)
    cell_m : the probe grids' cell; reach_m : how far in front rays start
    max_gap_m : (> 0) the longest run filled, and how far in front a covering surface may be
    strip_m : ``MeasureConfig.curve_strip_m``, the strip whose tilt the fillet would skew

    Returns
    -------
    :class:`CornerFill`
    """
    area_m2 = np.zeros((len(probes), NUM_CLASSES))
    weight, residual = planes.weight.copy(), planes.residual.copy()
    triangles = raycaster.mesh.triangles_m
    normal_xy = triangle_normals(triangles)[:, :2]
    for a, b in _concave_pairs(raycaster, planes):
        if probes[a] is None or labels[a] is None:
            continue
        fillet, to_corner = _fill_towards_corner(
            raycaster, planes, a, b, probes[a], labels[a], area_m2[a],
            cell_m=cell_m, reach_m=reach_m, max_gap_m=max_gap_m)
        if not fillet.any():
            continue
        end = (weight[:, a] > 0) & (to_corner <= max_gap_m + strip_m)  # the wall's last strip
        weight[end, a] = np.maximum(normal_xy[end] @ plane_frame(planes.azimuth_deg[a])[0][:2], 0)
        weight[fillet, a] = 0.0
        residual[fillet] = 0.0
    return CornerFill(area_m2, replace(planes, weight=weight, residual=residual))


def corner_line_xy(planes: FacadePlanes, a: int, b: int) -> np.ndarray:
    """(2,) world x, y (m) of the vertical line where planes ``a`` and ``b`` meet."""
    normals = np.array([plane_frame(planes.azimuth_deg[k])[0][:2] for k in (a, b)])
    return np.linalg.solve(normals, np.array([planes.offset_m[a], planes.offset_m[b]]))


def _concave_pairs(raycaster: Raycaster, planes: FacadePlanes) -> list[tuple[int, int]]:
    """Ordered pairs (a, b) of planes that meet in a concave corner (module docstring)."""
    counted = planes.weight > 0  # (F, K)
    centres = raycaster.mesh.triangles_m.mean(axis=1)
    areas = triangle_areas_m2(raycaster.mesh.triangles_m)
    lo, hi = np.cos(np.radians(CORNER_ANGLES_DEG[1])), np.cos(np.radians(CORNER_ANGLES_DEG[0]))
    pairs = []
    for a in range(len(planes.azimuth_deg)):
        normal_a = plane_frame(planes.azimuth_deg[a])[0]
        for b in range(len(planes.azimuth_deg)):
            normal_b = plane_frame(planes.azimuth_deg[b])[0]
            if a == b or not lo <= float(normal_a @ normal_b) <= hi:
                continue
            if _in_front(centres, areas, counted[:, b], normal_a, planes.offset_m[a]) and \
                    _in_front(centres, areas, counted[:, a], normal_b, planes.offset_m[b]):
                pairs.append((a, b))
    return pairs


def _in_front(centres: np.ndarray, areas: np.ndarray, which: np.ndarray, normal: np.ndarray,
              offset_m: float) -> bool:
    """Whether the area-weighted mean of the ``which`` faces lies in front of the plane."""
    if not which.any() or areas[which].sum() <= 0:
        return False
    return float(np.average(centres[which] @ normal, weights=areas[which])) > offset_m


def _fill_towards_corner(raycaster: Raycaster, planes: FacadePlanes, a: int, b: int,
                         probe: PlaneProbe, label: np.ndarray, area_m2: np.ndarray, *,
                         cell_m: float, reach_m: float, max_gap_m: float,
                         ) -> tuple[np.ndarray, np.ndarray]:
    """Add to ``area_m2`` (NUM_CLASSES,) what plane ``a``'s rows take towards its corner with
    plane ``b``; return the fillet's faces (F,) bool (those in front of the filled runs)
    and every face's distance (F,) m along ``a`` to the corner line (< 0 past it)."""
    normal, tangent = plane_frame(planes.azimuth_deg[a])
    corner = np.array([*corner_line_xy(planes, a, b), 0.0])
    u_corner = float(corner @ tangent)
    points = probe.points_m.reshape(*probe.shape, 3)
    u_cells = points[:, 0] @ tangent  # (U,) column centres along the plane
    toward = 1 if u_corner > u_cells.mean() else -1
    centres = raycaster.mesh.triangles_m.mean(axis=1)
    in_front = centres @ normal - planes.offset_m[a]
    to_corner = toward * (u_corner - centres @ tangent)  # >= 0 on A's side of the corner
    near = np.flatnonzero((in_front > 0) & (in_front <= max_gap_m) & (to_corner >= 0)
                          & (to_corner <= max_gap_m + cell_m))
    fillet = np.zeros(len(centres), dtype=bool)
    for j in range(probe.shape[1]):
        known = np.flatnonzero(label[:, j] >= 0)
        if len(known) == 0:
            continue
        last = known[-1] if toward > 0 else known[0]
        gap = toward * (u_corner - u_cells[last]) - cell_m / 2  # from its far edge to the corner
        if gap <= 0 or gap > max_gap_m:
            continue
        cells = max(1, int(np.ceil(gap / cell_m - 1e-6)))  # rays at the run's cell centres
        u = u_cells[last] + toward * (cell_m / 2 + gap * (np.arange(cells) + 0.5) / cells)
        z = points[last, j, 2]
        on_plane = (planes.offset_m[a] * normal + u[:, None] * tangent
                    + z * np.array([0.0, 0.0, 1.0]))
        face, t = raycaster.first_hit(on_plane + reach_m * normal,
                                      np.broadcast_to(-normal, on_plane.shape))
        depth = reach_m - t  # how far in front of the plane each ray meets a surface
        if not ((face >= 0) & (depth > 0) & (depth <= max_gap_m)).all():
            continue
        area_m2[label[last, j]] += gap * cell_m
        fillet[near[(np.abs(centres[near, 2] - z) * 2 <= cell_m)
                    & (to_corner[near] <= gap)]] = True  # the faces in front of the run
    return fillet, to_corner
