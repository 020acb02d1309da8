"""neural3d.extraction.measure_stages: the measurement as stages gives the numbers it gave as
one function, each switch turns off what its knob used to, and the stages are pure.

``_one_function`` is the measurement as it was before it became stages (commit 100bd86,
``measure_semantic_mesh``), written with the same module functions, with one change made
since (issue 32: the visibility cull's ground stops downward rays only within the mesh's
x/y box); each stage set must reproduce it exactly (same floats) on analytic meshes that
exercise every stage.
"""

from dataclasses import replace

import numpy as np
import pytest
from test_concave_corners import _l_prism
from test_measure import _recessed_box
from test_occluded_facade import _building

from envelope.classes import FACADE_CLASSES, NUM_CLASSES, SemanticClass
from envelope.geometry.raycast import Raycaster
from envelope.geometry.visibility import seen_from_outside
from neural3d.extraction.concave_corners import concave_corner_fill
from neural3d.extraction.extract_config import STAGES, ExtractConfig, without_stages
from neural3d.extraction.facade_groups import check_mesh_inputs, class_area_m2, group_faces
from neural3d.extraction.facade_planes import project_onto_facade_planes
from neural3d.extraction.facade_split import split_facade_area_by_probability
from neural3d.extraction.measure import measure_semantic_mesh, run_stages
from neural3d.extraction.measure_config import MeasureConfig, MeasureStages
from neural3d.extraction.measure_stages import (
    cull_hidden_faces,
    fill_occluded_facade,
    mesh_state,
    project_onto_planes,
)
from neural3d.extraction.occluded_facade import (
    front_seen_faces,
    occluded_facade_area_m2,
    occluded_facade_labels,
    probe_planes,
    seen_cell_labels,
)

CONFIG = MeasureConfig()
CLASSES = (SemanticClass.WINDOW, SemanticClass.WALL, SemanticClass.DOOR)


def _one_function(v, f, labels, probabilities, *, visibility=True, projected=True,
                  occlusion=True, corners=True):
    """The pre-stage measurement: (F, C) counted areas, facade planes or None, (K, C) added,
    and the whole building's window, wall and door m². The keywords are its old knobs:
    visibility_rays_per_sample > 0, count == "projected", occlusion_cell_m > 0,
    corner_max_gap_m > 0."""
    v, f, labels = check_mesh_inputs(v, f, labels)
    shares = class_area_m2(v, f, labels)
    if probabilities is not None:
        shares = split_facade_area_by_probability(shares, f, probabilities)
    areas = shares.copy()
    facade_area = areas[:, list(FACADE_CLASSES)].sum(axis=1)
    occlusion = projected and occlusion
    caster = Raycaster.from_triangles(v, f) if visibility or occlusion else None
    if visibility:
        facade = facade_area > 0
        hidden = facade & ~seen_from_outside(
            caster, facade, rays_per_sample=CONFIG.visibility_rays_per_sample,
            offset_m=CONFIG.ray_offset_m, min_escape_fraction=CONFIG.min_escape_fraction,
            ground=True, ground_box_xy_m=np.stack([v[:, :2].min(axis=0), v[:, :2].max(axis=0)]))
        areas[hidden] = 0.0
        facade_area[hidden] = 0.0
    group = group_faces(v, f, facade_area, CONFIG)
    planes, behind = None, np.zeros((0, NUM_CLASSES))
    counted = areas
    if projected:
        planes = project_onto_facade_planes(v, f, facade_area, group, config=CONFIG)
        behind = np.zeros((len(planes.azimuth_deg), NUM_CLASSES))
        if occlusion:
            def probe(planes):
                return probe_planes(caster, shares, planes, cell_m=CONFIG.occlusion_cell_m,
                                    slab_m=CONFIG.plane_slab_m,
                                    max_angle_deg=CONFIG.plane_max_angle_deg)
            probes = probe(planes)
            back = (facade_area == 0) & front_seen_faces(probes, len(f))
            if back.any():
                areas[back] = shares[back]
                facade_area = areas[:, list(FACADE_CLASSES)].sum(axis=1)
                group = group_faces(v, f, facade_area, CONFIG)
                planes = project_onto_facade_planes(v, f, facade_area, group, config=CONFIG)
                probes = probe(planes)
            cells = occluded_facade_labels(caster, shares, planes, probes,
                                           seen_cell_labels(shares, probes),
                                           slab_m=CONFIG.plane_slab_m,
                                           reach_m=CONFIG.occluder_reach_m)
            behind = occluded_facade_area_m2(probes, cells, cell_m=CONFIG.occlusion_cell_m)
            if corners:
                fill = concave_corner_fill(caster, planes, probes, cells,
                                           cell_m=CONFIG.occlusion_cell_m,
                                           reach_m=CONFIG.occluder_reach_m,
                                           max_gap_m=CONFIG.corner_max_gap_m,
                                           strip_m=CONFIG.curve_strip_m)
                behind, planes = behind + fill.area_m2, fill.planes
        counted = areas * (planes.weight.sum(axis=1) + planes.residual)[:, None]
    total = behind.sum(axis=0) if len(behind) else np.zeros(NUM_CLASSES)
    return areas, planes, behind, tuple(float(counted[:, c].sum() + total[c]) for c in CLASSES)


def _blurred_window_box():
    """The recessed box of test_measure with class probabilities: window blurred across
    its edges, so that the probability split moves area."""
    v, f, labels = _recessed_box(voxel_size_m=0.1)
    p = np.zeros((len(v), NUM_CLASSES))
    p[np.arange(len(v)), labels] = 0.8
    p += 0.2 / NUM_CLASSES
    return v, f, labels, p


@pytest.fixture(scope="module")
def meshes():
    # slots: 0.3 m square windows recessed 0.38 m, whose panes few hemisphere rays leave
    # (the visibility cull drops part of them) but a ray from straight in front meets
    return {"balcony": (*_building(), None), "chamfered_l": (*_l_prism(max_edge_m=0.2), None),
            "recessed_box": _blurred_window_box(),
            "slots": (*_recessed_box(voxel_size_m=0.1, window_m=(0.3, 0.3), depth_m=0.38),
                      None)}


# (mesh, new stages off, old knobs off): all on everywhere, each switch where it matters
CASES = [
    ("balcony", (), {}),
    ("chamfered_l", (), {}),
    ("recessed_box", (), {}),
    ("slots", (), {}),
    ("chamfered_l", ("concave_corner_fill",), {"corners": False}),
    ("balcony", ("plane_probe",), {"occlusion": False}),
    ("slots", ("visibility_cull",), {"visibility": False}),
    ("recessed_box", ("plane_projection",), {"projected": False}),
    ("recessed_box", ("probability_split",), {"split": False}),
]


@pytest.mark.slow
@pytest.mark.parametrize("name, off, knobs", CASES)
def test_the_stages_give_the_one_functions_numbers(meshes, name, off, knobs):
    v, f, labels, p = meshes[name]
    config = replace(CONFIG, stages=CONFIG.stages.without(*off))
    knobs = dict(knobs)
    probabilities = p if knobs.pop("split", True) else None
    areas, planes, behind, whole = _one_function(v, f, labels, probabilities, **knobs)
    state = run_stages(mesh_state(v, f, labels, p, config), config)
    np.testing.assert_array_equal(state.areas_m2, areas)
    if planes is None:
        assert state.planes is None
    else:
        for got, want in zip((state.planes.azimuth_deg, state.planes.offset_m,
                              state.planes.weight, state.planes.residual, state.added_m2),
                             (planes.azimuth_deg, planes.offset_m, planes.weight,
                              planes.residual, behind)):
            np.testing.assert_array_equal(got, want)
    m = measure_semantic_mesh(v, f, labels, config=config, vertex_probabilities=p)
    assert (m.window_area_m2, m.wall_area_m2, m.door_area_m2) == whole


@pytest.mark.slow
def test_every_stage_changes_something_on_the_meshes_made_for_it(meshes):
    """Each switch matters where its building has what it is for (so that the exact
    comparisons above compare different numbers)."""
    for name, stage in (("balcony", "occluded_fill"), ("chamfered_l", "concave_corner_fill"),
                        ("slots", "front_seen_readd"),
                        ("slots", "visibility_cull"),
                        ("recessed_box", "probability_split"),
                        ("recessed_box", "plane_projection")):
        v, f, labels, p = meshes[name]
        on = measure_semantic_mesh(v, f, labels, vertex_probabilities=p)
        off = measure_semantic_mesh(v, f, labels, vertex_probabilities=p, config=MeasureConfig(
            stages=MeasureStages().without(stage)))
        assert (on.window_area_m2, on.facade_area_m2) != (off.window_area_m2, off.facade_area_m2), \
            (name, stage)


def test_stages_do_not_change_the_state_they_are_given(meshes):
    v, f, labels, p = meshes["balcony"]
    state = mesh_state(v, f, labels, p, CONFIG)
    shares, areas = state.shares_m2.copy(), state.areas_m2.copy()
    culled = cull_hidden_faces(state, CONFIG)
    assert culled is not state
    np.testing.assert_array_equal(state.shares_m2, shares)
    np.testing.assert_array_equal(state.areas_m2, areas)


def test_a_stage_without_its_input_says_which_stage_is_missing(meshes):
    v, f, labels, p = meshes["balcony"]
    state = mesh_state(v, f, labels, p, CONFIG)
    with pytest.raises(ValueError, match="stage grouping"):
        project_onto_planes(state, CONFIG)
    with pytest.raises(ValueError, match="stage plane_probe"):
        fill_occluded_facade(state, CONFIG)


def test_switches_that_need_another_stage_are_refused_and_without_turns_them_off():
    with pytest.raises(ValueError, match="needs stage plane_probe"):
        MeasureStages(plane_probe=False)
    with pytest.raises(ValueError, match="concave_corner_fill needs stage plane_probe"):
        MeasureStages(plane_probe=False, front_seen_readd=False, occluded_fill=False)
    stages = MeasureStages().without("grouping")
    assert not any((stages.grouping, stages.plane_projection, stages.plane_probe,
                    stages.front_seen_readd, stages.occluded_fill, stages.concave_corner_fill))
    assert stages.probability_split and stages.visibility_cull
    with pytest.raises(ValueError, match="unknown measurement stage"):
        MeasureStages().without("corners")


def test_extract_config_switches_every_stage():
    assert STAGES[-2:] == ("roofed_hole_fill", "straight_walls") and len(STAGES) == 10
    config = without_stages(ExtractConfig(), "roofed_hole_fill", "occluded_fill")
    assert not config.roofed_hole_fill and not config.measure.stages.occluded_fill
    assert config.straight_walls
    assert config.measure.stages.concave_corner_fill
    assert without_stages(ExtractConfig()) == ExtractConfig()
    with pytest.raises(ValueError, match="unknown stage"):
        without_stages(ExtractConfig(), "everything")
