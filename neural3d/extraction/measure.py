"""Window, wall and door areas, WWR and per-facade figures from a mesh with per-vertex classes.

:func:`measure_semantic_mesh` runs the stages of
:mod:`neural3d.extraction.measure_stages` that
:class:`~neural3d.extraction.measure_config.MeasureStages` switches on, then counts:

- with facade planes (``plane_projection`` on), each facade triangle counts its
  share on the planes (its shadow on the plane it lies on; a cut corner on both
  walls; with its full area when near no plane but within ``facade_max_tilt_deg``
  of vertical), plus the area the fills added on each plane; the per-facade
  figures are the planes';
- without, every triangle counts its classes with its full area (the paper), and
  the per-facade figures are the groups' (none without ``grouping``).

Gross facade = wall + window + door (:class:`envelope.wwr.ClassAreas`); roof,
other and background never count.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from envelope.classes import FACADE_CLASSES, NUM_CLASSES, SemanticClass
from envelope.mesh import triangle_normals
from envelope.wwr import ClassAreas
from neural3d.extraction.facade_planes import azimuth_offset
from neural3d.extraction.measure_config import MeasureConfig
from neural3d.extraction.measure_stages import (
    MeasureState,
    cull_hidden_faces,
    fill_concave_corners,
    fill_occluded_facade,
    group_facades,
    mesh_state,
    probe_from_front,
    project_onto_planes,
    readd_front_seen,
    split_by_probability,
)


@dataclass(frozen=True)
class MeshFacade:
    """One facade of the mesh (a plane, or a group without planes).

    ``normal`` is the horizontal outward unit vector (world, z = 0) at
    ``azimuth_deg`` (counter-clockwise from +x); ``offset_m`` the plane's
    distance from the origin along it; ``height_m`` the z extent of its
    triangles and ``width_m`` the gross area over the height: exact for a
    rectangular facade, the arc length for a curved one, and, unlike an extent
    along the wall, blind to stray triangles whose normals join a neighbour.
    ``centre_m`` is the centroid (world m) of its triangles weighted by their
    facade-class area: where the facade is, for matching it to another's.
    """

    index: int
    normal: tuple[float, float, float]
    azimuth_deg: float
    offset_m: float
    window_area_m2: float
    wall_area_m2: float
    door_area_m2: float
    facade_area_m2: float
    wwr: float | None
    width_m: float
    height_m: float
    face_count: int
    centre_m: tuple[float, float, float]


@dataclass(frozen=True)
class MeshMeasurement:
    """Whole-building figures (m²) of a semantic mesh; ``wwr`` is None without facade area."""

    window_area_m2: float
    wall_area_m2: float
    door_area_m2: float
    facade_area_m2: float
    wwr: float | None
    facades: tuple[MeshFacade, ...]
    ungrouped_facade_area_m2: float


def measure_semantic_mesh(
    vertices_m: np.ndarray,
    faces: np.ndarray,
    vertex_labels: np.ndarray,
    *,
    config: MeasureConfig = MeasureConfig(),
    vertex_probabilities: np.ndarray | None = None,
) -> MeshMeasurement:
    """Window, wall, door and gross facade areas, WWR and per-facade figures of a semantic mesh.

    Parameters
    ----------
    vertices_m : (V, 3) float, world metres (z up, ground at z = 0)
    faces : (F, 3) int, outward-oriented
    vertex_labels : (V,) int class ids (:mod:`envelope.classes`)
    config : which stages run and their settings
    vertex_probabilities : optional (V, NUM_CLASSES) class probabilities, read by the
        ``probability_split`` stage

    Raises
    ------
    ValueError
        On malformed arrays or class ids outside the known classes.
    """
    state = mesh_state(vertices_m, faces, vertex_labels, vertex_probabilities, config)
    return measurement_of(run_stages(state, config))


def run_stages(state: MeasureState, config: MeasureConfig) -> MeasureState:
    """The stages ``config.stages`` switches on, in order, from ``state``
    (:func:`neural3d.extraction.measure_stages.mesh_state`)."""
    on = config.stages
    if on.probability_split:
        state = split_by_probability(state, config)
    if on.visibility_cull:
        state = cull_hidden_faces(state, config)
    if on.grouping:
        state = group_facades(state, config)
    if on.plane_projection:
        state = project_onto_planes(state, config)
    if on.plane_probe:
        state = probe_from_front(state, config)
    if on.front_seen_readd:
        state = readd_front_seen(state, config)
    if on.occluded_fill:
        state = fill_occluded_facade(state, config)
    if on.concave_corner_fill:
        state = fill_concave_corners(state, config)
    return state


def measurement_of(state: MeasureState) -> MeshMeasurement:
    """The whole-building and per-facade figures a state counts (module docstring)."""
    v, f, areas = state.vertices_m, state.faces, state.areas_m2
    facade_classes = list(FACADE_CLASSES)
    if state.planes is not None:
        planes = state.planes
        counted = areas * (planes.weight.sum(axis=1) + planes.residual)[:, None]
        facades = tuple(
            _facade_figures(k, v, f, areas * planes.weight[:, k, None], planes.weight[:, k] > 0,
                            plane=(az, off), added_m2=state.added_m2[k])
            for k, (az, off) in enumerate(zip(planes.azimuth_deg, planes.offset_m)))
        ungrouped = float((areas[:, facade_classes].sum(axis=1) * planes.residual).sum())
        added = state.added_m2.sum(axis=0)
    else:
        group = state.group if state.group is not None else np.full(len(f), -1)
        counted = areas
        facades = tuple(_facade_figures(i, v, f, areas, group == i)
                        for i in range(int(group.max(initial=-1)) + 1))
        ungrouped = float(areas[group < 0][:, facade_classes].sum())
        added = np.zeros(NUM_CLASSES)
    total = _class_areas(counted, added)
    return MeshMeasurement(
        window_area_m2=total.window_m2,
        wall_area_m2=total.wall_m2,
        door_area_m2=total.door_m2,
        facade_area_m2=total.gross_m2,
        wwr=total.wwr,
        facades=facades,
        ungrouped_facade_area_m2=ungrouped,
    )


def _class_areas(counted_m2: np.ndarray, added_m2: np.ndarray) -> ClassAreas:
    """Window, wall and door of (F, NUM_CLASSES) counted areas plus (NUM_CLASSES,) added, m²."""
    return ClassAreas(*(float(counted_m2[:, c].sum() + added_m2[c]) for c in
                        (SemanticClass.WINDOW, SemanticClass.WALL, SemanticClass.DOOR)))


def _facade_figures(
    index: int, vertices_m: np.ndarray, faces: np.ndarray, areas: np.ndarray, mask: np.ndarray,
    plane: tuple[float, float] | None = None, added_m2: np.ndarray | None = None,
) -> MeshFacade:
    """Figures of the triangles in ``mask``; ``plane`` (azimuth deg, offset m) if known;
    ``added_m2`` (NUM_CLASSES,) where the mesh has no facade, added to the classes' areas."""
    tri = vertices_m[faces[mask]]
    a = areas[mask]
    total = _class_areas(a, np.zeros(NUM_CLASSES) if added_m2 is None else added_m2)
    weight = a[:, list(FACADE_CLASSES)].sum(axis=1)
    azimuth, offset = plane if plane is not None else azimuth_offset(
        triangle_normals(tri), tri.mean(axis=1)[:, :2], weight)
    azimuth, offset = float(azimuth), float(offset)
    u = np.array([np.cos(np.radians(azimuth)), np.sin(np.radians(azimuth))])
    height = float(tri[..., 2].max() - tri[..., 2].min())
    return MeshFacade(
        index=index,
        normal=(round(float(u[0]), 12) + 0.0, round(float(u[1]), 12) + 0.0, 0.0),
        azimuth_deg=float(azimuth),
        offset_m=offset,
        window_area_m2=total.window_m2,
        wall_area_m2=total.wall_m2,
        door_area_m2=total.door_m2,
        facade_area_m2=total.gross_m2,
        wwr=total.wwr,
        width_m=total.gross_m2 / height if height > 0 else 0.0,
        height_m=height,
        face_count=int(mask.sum()),
        centre_m=tuple(float(c) for c in np.average(tri.mean(axis=1), axis=0, weights=weight)),
    )
