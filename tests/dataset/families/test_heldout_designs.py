"""The held-out designs: each one's truth in closed form, its mesh closed and in agreement."""

import numpy as np
import pytest
import shapely
import trimesh
from building_checks import (
    check_areas,
    check_building,
    check_closed_bodies,
    check_no_coplanar_overlap,
)
from shapely.geometry import MultiLineString, Polygon
from shapely.ops import polygonize, unary_union

from dataset.families.heldout import make_heldout, sample_heldout_params
from dataset.families.heldout_params import HELDOUT_MODELS, HeldoutParams, default_heldout_params
from dataset.families.heldout_plan import STEPS, bow_footprint
from dataset.families.heldout_recess import (
    BALCONY_DOOR_HEIGHT_M,
    RAILING_GAP_M,
    RAILING_HEIGHT_M,
)
from dataset.families.heldout_roofs import HIP_OVERHANG_M, SHELL_GAP_M, SHELL_THICKNESS_M
from dataset.families.heldout_setback import tier_floors
from envelope.footprint import geojson_to_polygon
from envelope.wwr import ClassAreas


@pytest.mark.parametrize("model", [m for m in HELDOUT_MODELS if m != "slope"])
def test_sampled_design_agrees_with_its_mesh(model):
    params = sample_heldout_params(np.random.default_rng(5), model)
    building = make_heldout(params, seed=5)
    check_building(building)
    t = building.truth
    assert t.type == "realistic" and t.name == model and t.extra["params"]["model"] == model
    assert 0.1 < t.wwr < 0.35 and t.door_area_m2 > 0


def test_hip_roof_walls_are_rectangles_and_its_slab_hides_a_strip():
    p = HeldoutParams("hip", width_m=13.0, depth_m=9.0, floors=2, floor_height_m=3.0, roof_m=3.0)
    building = make_heldout(p)
    t = building.truth
    assert check_closed_bodies(building) == 2  # house and roof slab
    tan = 3.0 / 4.5
    cos = 1 / np.hypot(1.0, tan)
    assert t.height_m == pytest.approx(6.0 + 3.0 + (SHELL_GAP_M + SHELL_THICKNESS_M) / cos)
    assert [f.facade_area_m2 for f in t.facades] == pytest.approx([78.0, 54.0, 78.0, 54.0])
    strip = HIP_OVERHANG_M * tan - SHELL_GAP_M / cos
    for f, length in zip(t.facades, (13.0, 9.0, 13.0, 9.0)):
        assert f.wall_area_m2 - f.visible_wall_area_m2 == pytest.approx(length * strip)


def test_mansard_is_seen_whole_under_its_steep_roof():
    p = default_heldout_params("mansard")
    t = make_heldout(p).truth
    eave = p.floors * p.floor_height_m
    assert t.height_m == pytest.approx(eave + p.roof_m)
    assert t.facade(1).facade_area_m2 == pytest.approx(p.width_m * eave)
    assert t.visible_areas_m2() == ClassAreas(t.window_area_m2, t.wall_area_m2, t.door_area_m2)


def test_setback_tiers_are_their_own_facades():
    p = default_heldout_params("setback")
    t = make_heldout(p).truth
    counts = tier_floors(p.floors)
    assert sum(counts) == p.floors and len(t.facades) == 12
    fh, s = p.floor_height_m, p.setback_m
    heights = [counts[0] * fh, counts[1] * fh, counts[2] * fh + p.roof_m]
    for tier in range(3):
        south = t.facade(4 * tier + 1)
        assert south.width_m == pytest.approx(p.width_m - 2 * tier * s)
        assert south.facade_area_m2 == pytest.approx(south.width_m * heights[tier])
    assert t.footprint_area_m2 == pytest.approx(p.width_m * p.depth_m)


def test_loggia_facade_keeps_its_front_area_and_the_passage_notches_the_footprint():
    p = default_heldout_params("loggia")
    t = make_heldout(p).truth
    south = t.facade(1)
    height = p.floors * p.floor_height_m + p.roof_m
    assert south.width_m == pytest.approx(p.width_m)
    assert south.facade_area_m2 == pytest.approx(p.width_m * height)  # back walls fill the holes
    pa, pb = t.extra["recesses"]["passage_u_m"]
    assert t.footprint_area_m2 == pytest.approx(p.width_m * p.depth_m - p.recess_m * (pb - pa))
    assert geojson_to_polygon(t.footprint).contains(Polygon([(-0.1, -p.depth_m / 2 + 0.1),
                                                             (0.1, -p.depth_m / 2 + 0.1),
                                                             (0.1, 0.0)])) is False
    # Each loggia's railing hides its balcony door's lower part and the wall around it.
    loggias = t.extra["recesses"]["loggias"]
    width = (pb - pa) / 2 - 2 * 0.3  # two bays, minus the wall kept at each side
    railing = (width - 2 * RAILING_GAP_M) * (RAILING_HEIGHT_M - RAILING_GAP_M)
    door = p.window_width_m * (RAILING_HEIGHT_M - 0.1)
    assert BALCONY_DOOR_HEIGHT_M > RAILING_HEIGHT_M
    assert south.window_area_m2 - south.visible_window_area_m2 == pytest.approx(loggias * door)
    assert south.wall_area_m2 - south.visible_wall_area_m2 == pytest.approx(
        loggias * (railing - door))


def test_corner_has_a_sixty_and_a_hundred_and_twenty_degree_corner():
    p = default_heldout_params("corner")
    t = make_heldout(p).truth
    shift = p.depth_m / np.tan(np.radians(60.0))
    assert t.footprint_area_m2 == pytest.approx(p.depth_m * (2 * p.width_m - shift) / 2)
    east = t.facade(2)
    assert east.width_m == pytest.approx(p.depth_m / np.sin(np.radians(60.0)))
    np.testing.assert_allclose(east.normal, [np.sin(np.radians(60.0)), np.cos(np.radians(60.0)),
                                             0.0], atol=1e-12)


def test_bow_front_is_one_curved_facade_of_the_given_radius():
    p = default_heldout_params("bow")
    t = make_heldout(p).truth
    w, r = p.width_m, p.radius_m
    alpha = np.arcsin(w / 2 / r)
    _, n = bow_footprint(p.width_m, p.depth_m, r)
    front = t.facade(1)
    assert front.curved and t.extra["curved_facade"]["facets"] == n
    assert front.width_m == pytest.approx(2 * n * r * np.sin(alpha / n))
    np.testing.assert_allclose(front.normal, [0.0, -1.0, 0.0], atol=1e-12)
    segment = n / 2 * r * r * np.sin(2 * alpha / n) - w / 2 * r * np.cos(alpha)
    assert t.footprint_area_m2 == pytest.approx(w * p.depth_m + segment)


def test_sawtooth_steps_are_many_small_facades():
    p = default_heldout_params("sawtooth")
    t = make_heldout(p).truth
    s = p.step_m
    assert len(t.facades) == 4 + 2 * STEPS
    assert sum(np.isclose(f.width_m, s) for f in t.facades) == 2 * STEPS
    assert t.footprint_area_m2 == pytest.approx(p.width_m * p.depth_m
                                                - s * s * STEPS * (STEPS + 1) / 2)


def test_slope_facades_stand_on_the_terrain_and_the_footprint_is_the_plan():
    p = default_heldout_params("slope")
    building = make_heldout(p)
    t = building.truth
    check_areas(building)
    check_no_coplanar_overlap(building)
    assert check_closed_bodies(building) == 1
    w, d, rise = p.width_m, p.depth_m, p.rise_m
    above = p.floors * p.floor_height_m + p.roof_m  # wall above the back's ground level
    south, east, north, west = t.facades
    assert south.facade_area_m2 == pytest.approx(w * (rise + above))
    assert north.facade_area_m2 == pytest.approx(w * above)
    assert east.facade_area_m2 == west.facade_area_m2 == pytest.approx(d * (rise + above)
                                                                       - d * rise / 2)
    assert t.height_m == pytest.approx(rise + above)
    # The section just above the terrain plane, seen in plan, is the footprint.
    normal = np.array([0.0, -rise / d, 1.0])
    tm = trimesh.Trimesh(building.mesh.vertices_m, building.mesh.faces, process=False)
    segments = trimesh.intersections.mesh_plane(tm, normal / np.linalg.norm(normal),
                                                [0.0, 0.0, rise / 2 + 0.01])
    lines = shapely.set_precision(MultiLineString([s[:, :2] for s in segments]), 1e-7)
    section = unary_union(list(polygonize(unary_union(lines))))
    truth = geojson_to_polygon(t.footprint)
    assert section.symmetric_difference(truth).area < 1e-6 * truth.area
    assert t.footprint_area_m2 == pytest.approx(w * d)
    # Nothing stands on the back's ground below the terrain there.
    back = building.mesh.vertices_m[np.isclose(building.mesh.vertices_m[:, 1], d / 2)]
    assert back[:, 2].min() == pytest.approx(rise)


def test_bad_parameters_raise_helpful_errors():
    with pytest.raises(ValueError, match="unknown held-out design"):
        HeldoutParams("castle")
    with pytest.raises(ValueError, match="corner_deg"):
        HeldoutParams("corner", corner_deg=90.0)
    with pytest.raises(ValueError, match="width >= depth"):
        make_heldout(HeldoutParams("hip", width_m=9.0, depth_m=9.0))
    with pytest.raises(ValueError, match="more than a storey"):
        make_heldout(HeldoutParams("slope", rise_m=4.0))
