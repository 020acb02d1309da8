"""Facade seen straight from the front, and facade hidden behind balconies filled from its column.

A balcony's railing and slab hide the lower part of the wall and of the balcony
door behind them from every camera but a few steep ones, so a trained field
closes or dents that space and its mesh has no facade there; the truth counts
the facade behind an occluder (an auditor needs the door's whole area). And the
wall at the back of a balcony, between railing and slab, lets few of the
hemisphere rays of the visibility cull (:mod:`neural3d.extraction.measure_stages`)
escape, so that test drops it although a camera in front sees it.

So, on each facade plane of :class:`neural3d.extraction.facade_planes.FacadePlanes`,
a grid of ``occlusion_cell_m`` squares over the u/z extent of the plane's
triangles is probed with rays along the plane's inward normal:

- a cell is *seen* when a ray from ``plane_slab_m`` in front of the plane first
  meets, within the slab, a facade triangle near the plane that faces it (within
  ``plane_max_angle_deg``): :func:`front_seen_faces` gives these triangles, and
  the measurement counts them even where the hemisphere test dropped them; a
  seen cell's class is its triangle's largest facade class;
- a cell is *occluded* when a ray from ``occluder_reach_m`` in front first
  meets, before the slab, a surface whose largest class is not a facade class
  (other: a balcony, a railing; roof: an overhang).

In each column (fixed u), a run of unseen cells with a seen cell right above it
and a seen cell or the ground (the grid's bottom) right below, at least half of
whose cells are occluded, is filled (:func:`occluded_facade_labels`,
:func:`occluded_facade_area_m2`): each cell
takes the class of the nearest seen cell in the column (the one above on a tie;
the one above only, at the ground), and its area is added to that plane's
figures. Under a balcony door the upper half of the hole then continues the door
and the lower half the wall below. A hole with no occluder in front (the end of
a wall, a deep recess) or not closed above and below stays empty.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from envelope.classes import FACADE_CLASSES, NUM_CLASSES
from envelope.geometry.raycast import Raycaster
from neural3d.extraction.facade_planes import FacadePlanes, plane_frame

FACADE_IDS = tuple(int(c) for c in FACADE_CLASSES)


@dataclass(frozen=True)
class PlaneProbe:
    """The cells of one plane's grid and what a ray from in front meets at each.

    ``shape`` (U, Z): cells along the plane (u) and up (z), z increasing;
    ``points_m`` (U*Z, 3) cell centres on the plane, world metres; ``face`` (U*Z,)
    the triangle a ray from the slab's front meets first, -1 none; ``seen``
    (U*Z,) whether that is a facade triangle near the plane facing it.
    """

    shape: tuple[int, int]
    points_m: np.ndarray
    face: np.ndarray
    seen: np.ndarray


def probe_planes(
    raycaster: Raycaster, class_area_m2: np.ndarray, planes: FacadePlanes, *,
    cell_m: float, slab_m: float, max_angle_deg: float,
) -> list[PlaneProbe | None]:
    """One :class:`PlaneProbe` per plane (None for a plane that counts no triangle).

    Parameters
    ----------
    raycaster : over the measured mesh (world metres)
    class_area_m2 : (F, NUM_CLASSES) each face's area shared among classes
        (:func:`neural3d.extraction.facade_groups.class_area_m2`)
    planes : the mesh's facade planes (``weight`` (F, K): which faces count on plane k)
    cell_m, slab_m : grid cell and the planes' slab half-width, metres
    max_angle_deg : how far a face's normal may turn from the plane's and face it
    """
    mesh = raycaster.mesh
    is_facade = class_area_m2[:, list(FACADE_IDS)].sum(axis=1) > 0
    centres = mesh.triangles_m.mean(axis=1)
    probes: list[PlaneProbe | None] = []
    for k, (azimuth, offset) in enumerate(zip(planes.azimuth_deg, planes.offset_m)):
        on_plane = planes.weight[:, k] > 0
        if not on_plane.any():
            probes.append(None)
            continue
        normal, tangent = plane_frame(azimuth)
        corners = mesh.triangles_m[on_plane].reshape(-1, 3)
        uu, zz = np.meshgrid(_centres(corners @ tangent, cell_m),
                             _centres(corners[:, 2], cell_m), indexing="ij")  # (U, Z)
        points = (offset * normal + uu.reshape(-1, 1) * tangent
                  + zz.reshape(-1, 1) * np.array([0.0, 0.0, 1.0]))
        near = (is_facade & (np.abs(centres @ normal - offset) <= slab_m)
                & (raycaster.face_normals @ normal >= np.cos(np.radians(max_angle_deg))))
        face, t = raycaster.first_hit(points + slab_m * normal,
                                      np.broadcast_to(-normal, points.shape))
        hit = face >= 0
        seen = np.zeros(len(points), dtype=bool)
        seen[hit] = near[face[hit]] & (t[hit] <= 2 * slab_m)
        probes.append(PlaneProbe(uu.shape, points, face, seen))
    return probes


def front_seen_faces(probes: list[PlaneProbe | None], face_count: int) -> np.ndarray:
    """(F,) bool: the faces some plane's probe sees first from in front."""
    seen = np.zeros(face_count, dtype=bool)
    for probe in probes:
        if probe is not None:
            seen[probe.face[probe.seen]] = True
    return seen


def seen_cell_labels(class_area_m2: np.ndarray,
                     probes: list[PlaneProbe | None]) -> list[np.ndarray | None]:
    """Per plane, the (U, Z) class of each cell of its probe grid: the seen triangle's
    largest facade class, -1 for a cell not seen; None where ``probes`` has none.

    ``class_area_m2`` (F, NUM_CLASSES): the faces' class areas the probes were made with.
    """
    facade_label = np.array(FACADE_IDS)[np.argmax(class_area_m2[:, list(FACADE_IDS)], axis=1)]
    return [None if probe is None else
            np.where(probe.seen, facade_label[np.maximum(probe.face, 0)], -1).reshape(probe.shape)
            for probe in probes]


def occluded_facade_labels(
    raycaster: Raycaster, class_area_m2: np.ndarray, planes: FacadePlanes,
    probes: list[PlaneProbe | None], seen_labels: list[np.ndarray | None], *,
    slab_m: float, reach_m: float,
) -> list[np.ndarray | None]:
    """Per plane, the (U, Z) class each cell of its probe grid takes: its class in
    ``seen_labels`` (:func:`seen_cell_labels`), or, for facade hidden behind an occluder,
    the class it is filled with (module docstring); -1 for a cell neither seen nor
    filled. None where ``probes`` has none.

    ``probes`` from :func:`probe_planes` on the same planes; ``reach_m``: how far in
    front of a plane occluders are looked for.
    """
    occluder = ~np.isin(np.argmax(class_area_m2, axis=1), FACADE_IDS)  # (F,)
    out: list[np.ndarray | None] = []
    for k, (probe, seen) in enumerate(zip(probes, seen_labels)):
        if probe is None:
            out.append(None)
            continue
        normal, _ = plane_frame(planes.azimuth_deg[k])
        face, t = raycaster.first_hit(probe.points_m + reach_m * normal,
                                      np.broadcast_to(-normal, probe.points_m.shape))
        hit = face >= 0
        occluded = np.zeros(len(face), dtype=bool)
        occluded[hit] = occluder[face[hit]] & (t[hit] < reach_m - slab_m)
        filled = _fill_columns(seen, occluded.reshape(probe.shape))
        out.append(np.where(seen >= 0, seen, filled))
    return out


def occluded_facade_area_m2(probes: list[PlaneProbe | None],
                            labels: list[np.ndarray | None], *, cell_m: float) -> np.ndarray:
    """Facade area (m²) hidden behind occluders on each plane, by class: the filled cells
    of :func:`occluded_facade_labels` (``labels``) on the ``cell_m`` grids of ``probes``.
    Returns (K, NUM_CLASSES) m²."""
    out = np.zeros((len(probes), NUM_CLASSES))
    for k, (probe, label) in enumerate(zip(probes, labels)):
        if probe is not None:
            filled = label[~probe.seen.reshape(probe.shape)]
            out[k] = np.bincount(filled[filled >= 0], minlength=NUM_CLASSES) * cell_m ** 2
    return out


def _centres(values_m: np.ndarray, cell_m: float) -> np.ndarray:
    """Centres of the ``cell_m`` cells that cover [min, max] of ``values_m``."""
    lo, hi = float(values_m.min()), float(values_m.max())
    n = max(1, int(np.ceil((hi - lo) / cell_m)))
    return lo + (np.arange(n) + 0.5) * cell_m


def _fill_columns(label: np.ndarray, occluded: np.ndarray) -> np.ndarray:
    """(U, Z) class to add per cell (-1: none) from seen classes ``label`` (-1 unseen).

    Along z (increasing), a run of unseen cells whose next cell up is seen, whose
    next cell down is seen or below the grid, and at least half of which is
    ``occluded``, takes the class of the nearest of those two seen cells (the
    one above on a tie or at the grid's bottom).
    """
    filled = np.full(label.shape, -1, dtype=np.int64)
    for i in range(label.shape[0]):
        column = label[i]
        z = 0
        while z < len(column):
            if column[z] >= 0:
                z += 1
                continue
            start = z
            while z < len(column) and column[z] < 0:
                z += 1
            closed = (start == 0 or column[start - 1] >= 0) and z < len(column)
            if closed and 2 * occluded[i, start:z].sum() >= z - start:
                lower = (z - start) // 2 if start > 0 else 0  # cells nearer the one below
                filled[i, start:start + lower] = column[start - 1]
                filled[i, start + lower:z] = column[z]
    return filled
