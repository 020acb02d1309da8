"""The stages of neural3d's measurement: pure functions from one :class:`MeasureState` to the next.

:func:`neural3d.extraction.measure.measure_semantic_mesh` runs them in this
order, each behind its switch in :class:`~neural3d.extraction.measure_config.MeasureStages`,
and counts the last state. Each stage says what it assumes about buildings and
where that assumption biases the figures; ``bench/neural3d_stages.py`` measures
what each one changes on trained fields.

Every stage reads the settings of :class:`~neural3d.extraction.measure_config.MeasureConfig`
it needs and returns a new state; none changes the arrays it is given. A stage
whose input is missing (its switch on, the stage it needs off) raises ValueError.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from envelope.classes import FACADE_CLASSES, NUM_CLASSES
from envelope.geometry.raycast import Raycaster
from envelope.geometry.visibility import seen_from_outside
from neural3d.extraction.concave_corners import concave_corner_fill
from neural3d.extraction.facade_groups import check_mesh_inputs, class_area_m2, group_faces
from neural3d.extraction.facade_planes import FacadePlanes, project_onto_facade_planes
from neural3d.extraction.facade_split import split_facade_area_by_probability
from neural3d.extraction.measure_config import MeasureConfig
from neural3d.extraction.occluded_facade import (
    PlaneProbe,
    front_seen_faces,
    occluded_facade_area_m2,
    occluded_facade_labels,
    probe_planes,
    seen_cell_labels,
)


@dataclass(frozen=True)
class MeasureState:
    """A semantic mesh and what the stages so far found on it (world metres, z up).

    ``vertices_m`` (V, 3), ``faces`` (F, 3) outward, ``vertex_labels`` (V,) class ids,
    ``vertex_probabilities`` (V, NUM_CLASSES) or None. ``shares_m2`` (F, NUM_CLASSES):
    each triangle's area shared among classes (what the probes read); ``areas_m2`` the
    same where the triangle counts, 0 where the visibility cull hid it.
    ``raycaster``: over the mesh, built once when a stage casts rays. Then, once their
    stages ran (None before): ``group`` (F,) facade group (-1 none); ``planes`` the
    facade planes and each triangle's share on them; ``probes`` and ``cell_labels``
    each plane's probe grid and (U, Z) cell classes (-1 unknown); ``added_m2``
    (K, NUM_CLASSES) facade area each plane gains where the mesh has none.
    """

    vertices_m: np.ndarray
    faces: np.ndarray
    vertex_labels: np.ndarray
    vertex_probabilities: np.ndarray | None
    shares_m2: np.ndarray
    areas_m2: np.ndarray
    raycaster: Raycaster | None
    group: np.ndarray | None = None
    planes: FacadePlanes | None = None
    probes: tuple[PlaneProbe | None, ...] | None = None
    cell_labels: tuple[np.ndarray | None, ...] | None = None
    added_m2: np.ndarray | None = None

    @property
    def facade_area_m2(self) -> np.ndarray:
        """(F,) wall + window + door area of each triangle that counts, m²."""
        return self.areas_m2[:, list(FACADE_CLASSES)].sum(axis=1)


def mesh_state(vertices_m: np.ndarray, faces: np.ndarray, vertex_labels: np.ndarray,
               vertex_probabilities: np.ndarray | None, config: MeasureConfig) -> MeasureState:
    """The first state: checked arrays, each triangle's area shared among classes by the
    fraction of its vertices in each class (the paper), and the raycaster if a stage
    that casts rays is on.

    Raises
    ------
    ValueError
        On malformed arrays or class ids outside the known classes.
    """
    v, f, labels = check_mesh_inputs(vertices_m, faces, vertex_labels)
    shares = class_area_m2(v, f, labels)
    rays = config.stages.visibility_cull or config.stages.plane_probe
    caster = Raycaster.from_triangles(v, f) if rays and len(f) else None
    return MeasureState(v, f, labels, vertex_probabilities, shares, shares, caster)


def split_by_probability(state: MeasureState, config: MeasureConfig) -> MeasureState:
    """Each triangle's facade area re-split among wall, window and door by the mean of its
    corners' class probabilities (:mod:`neural3d.extraction.facade_split`); nothing
    without probabilities.

    Assumes the semantic head's probabilities are calibrated among the facade classes,
    so that a blurred window indicator still integrates to the opening's area. Biases
    window area by the head's over- or under-confidence at openings' edges; gross
    facade area does not move.
    """
    p = state.vertex_probabilities
    if p is None:
        return state
    shares = split_facade_area_by_probability(state.shares_m2, state.faces, p)
    areas = shares if state.areas_m2 is state.shares_m2 else split_facade_area_by_probability(
        state.areas_m2, state.faces, p)
    return replace(state, shares_m2=shares, areas_m2=areas)


def cull_hidden_faces(state: MeasureState, config: MeasureConfig) -> MeasureState:
    """Facade triangles no ray leaves count for nothing
    (:func:`envelope.geometry.visibility.seen_from_outside`: ``visibility_rays_per_sample``
    rays from 4 points of each face, at least ``min_escape_fraction`` must escape; the
    ground, the plane z = 0 within the mesh's x/y box, stops a downward ray that meets it
    there, so the inner sides of walls over an open underside see nothing, while the wall
    under an eave sees down past the building as a camera on the ground sees it).

    Assumes facade is surface open to the outside above the ground at z = 0: what a
    trained field closes inside the building (a blob behind the windows, the sides of a
    tunnel at a door) is no facade. Biases low where facade is deeply recessed or
    nearly enclosed (the back of a balcony, a narrow courtyard, a deep slot); the
    front-seen re-add gives back what a ray from straight in front meets. On perfect
    geometry (``bench/oracle_measure.py``) it takes 0.6 % of the facade of the paper
    preset's house (its wall under the eaves' sloping soffit, which only steep
    downward rays leave), 4.5 % of ``heldout_loggia``'s (its facade error goes from
    +5.8 % to +1.3 %) and at most 0.05 % on the other buildings of ``paper`` and
    ``heldout`` (docs/neural3d-extract.md, section Oracle).
    """
    if state.raycaster is None:
        return state
    facade = state.facade_area_m2 > 0
    ground_box = np.stack([state.vertices_m[:, :2].min(axis=0),
                           state.vertices_m[:, :2].max(axis=0)])
    seen = seen_from_outside(state.raycaster, facade,
                             rays_per_sample=config.visibility_rays_per_sample,
                             offset_m=config.ray_offset_m,
                             min_escape_fraction=config.min_escape_fraction, ground=True,
                             ground_box_xy_m=ground_box)
    areas = state.areas_m2.copy()
    areas[facade & ~seen] = 0.0
    return replace(state, areas_m2=areas)


def group_facades(state: MeasureState, config: MeasureConfig) -> MeasureState:
    """Facade groups from the azimuths and offsets of the counted facade triangles
    (:mod:`neural3d.extraction.facade_groups`).

    Assumes vertical facades (within ``facade_max_tilt_deg``), walls at least
    ``min_facade_separation_deg`` apart in azimuth, parallel walls at least
    ``plane_gap_m`` apart and two facades of one plane at least ``plane_extent_gap_m``
    apart along it. Biases the per-facade figures, not the whole building's: a curved
    wall is cut into arbitrary segments, two walls closer in azimuth or offset merge, a
    wall broken by a deep recess wider than ``plane_extent_gap_m`` becomes two facades,
    and facades smaller than the minimum group are left out.
    """
    return replace(state, group=group_faces(state.vertices_m, state.faces,
                                            state.facade_area_m2, config))


def project_onto_planes(state: MeasureState, config: MeasureConfig) -> MeasureState:
    """Facade planes from the groups; each facade triangle counts its shadow on the plane
    it lies on and faces (:mod:`neural3d.extraction.facade_planes`).

    Assumes planar facades with openings in the wall plane, as the truth counts them:
    the sides of a recess, reveals, wavy walls and the underside a field may close
    the building with at the ground count their shadow (often nothing). Strips
    ``curve_strip_m`` wide follow a curved wall. Biases low on a genuinely tilted
    facade (a mansard: its area times the cosine of its tilt).
    """
    group = _needs(state.group, "grouping")
    planes = project_onto_facade_planes(state.vertices_m, state.faces, state.facade_area_m2,
                                        group, config=config)
    return replace(state, planes=planes,
                   added_m2=np.zeros((len(planes.azimuth_deg), NUM_CLASSES)))


def probe_from_front(state: MeasureState, config: MeasureConfig) -> MeasureState:
    """Each plane probed with rays along its inward normal on a grid of
    ``occlusion_cell_m`` cells (:mod:`neural3d.extraction.occluded_facade`): which facade
    triangle a ray from ``plane_slab_m`` in front meets first, and its class per cell.

    Changes no figure by itself; the re-add and the two fills read it. Assumes a
    facade is seen from straight in front; a cell is as fine as ``occlusion_cell_m``.
    """
    planes = _needs(state.planes, "plane_projection")
    probes = tuple(probe_planes(_rays(state), state.shares_m2, planes,
                                cell_m=config.occlusion_cell_m, slab_m=config.plane_slab_m,
                                max_angle_deg=config.plane_max_angle_deg))
    return replace(state, probes=probes,
                   cell_labels=tuple(seen_cell_labels(state.shares_m2, list(probes))))


def readd_front_seen(state: MeasureState, config: MeasureConfig) -> MeasureState:
    """Facade triangles the visibility cull dropped but a probe meets first from straight in
    front count again; grouping, planes and probes are then found again.

    Assumes what a ray from straight in front meets first is facade a camera sees
    (the wall at the back of a balcony). Biases high only where a closed pocket of
    the mesh opens towards a facade plane.
    """
    probes = _needs(state.probes, "plane_probe")
    back = (state.facade_area_m2 == 0) & front_seen_faces(list(probes), len(state.faces))
    if not back.any():
        return state
    areas = state.areas_m2.copy()
    areas[back] = state.shares_m2[back]
    state = group_facades(replace(state, areas_m2=areas), config)
    return probe_from_front(project_onto_planes(state, config), config)


def fill_occluded_facade(state: MeasureState, config: MeasureConfig) -> MeasureState:
    """Facade hidden behind a balcony or another non-facade solid in front of its plane is
    filled from the nearest seen cells above and below it in its column
    (:func:`neural3d.extraction.occluded_facade.occluded_facade_labels`).

    Assumes a facade continues behind an occluder as it is above and below it: the
    upper half of the hole continues the class above, the lower half the class below
    (the one above where the hole reaches the ground, z = 0). Biases where that is
    not so: a window wholly hidden between wall above and below is counted as wall.
    """
    probes = _needs(state.probes, "plane_probe")
    planes, labels = _needs(state.planes, "plane_projection"), state.cell_labels
    filled = tuple(occluded_facade_labels(_rays(state), state.shares_m2, planes,
                                          list(probes), list(labels),
                                          slab_m=config.plane_slab_m,
                                          reach_m=config.occluder_reach_m))
    behind = occluded_facade_area_m2(list(probes), list(filled), cell_m=config.occlusion_cell_m)
    return replace(state, cell_labels=filled, added_m2=state.added_m2 + behind)


def fill_concave_corners(state: MeasureState, config: MeasureConfig) -> MeasureState:
    """Each wall's rows continued to the line where it meets another wall in a concave
    corner the field filled, up to ``corner_max_gap_m``; the fillet's own faces no
    longer count (:mod:`neural3d.extraction.concave_corners`).

    Assumes sharp corners: walls 45-135 degrees apart meet in a vertical line, and a
    fillet or chamfer there is the field's doing. Biases high on a building whose
    inner corner really is chamfered or rounded (a chamfer with 1.2 m legs on a
    6 m high L: 240 m² counted where 235.8 m² are built, issue 32).
    """
    probes = _needs(state.probes, "plane_probe")
    corners = concave_corner_fill(_rays(state), state.planes, list(probes),
                                  list(state.cell_labels), cell_m=config.occlusion_cell_m,
                                  reach_m=config.occluder_reach_m,
                                  max_gap_m=config.corner_max_gap_m,
                                  strip_m=config.curve_strip_m)
    return replace(state, planes=corners.planes, added_m2=state.added_m2 + corners.area_m2)


def _needs(value, stage: str):
    if value is None:
        raise ValueError(f"this measurement stage needs the output of stage {stage}, "
                         "which did not run")
    return value


def _rays(state: MeasureState) -> Raycaster:
    if state.raycaster is None:
        raise ValueError("this measurement stage casts rays: make the state with "
                         "mesh_state(...) with plane_probe on, on a mesh with faces")
    return state.raycaster
