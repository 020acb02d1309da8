"""metrics.score.facade_match: a method's own facades take the truth's facade ids by normal and
centre."""

from dataclasses import replace

import numpy as np
import pytest
from sdf_shapes import banded_labels, cylinder_sdf

from dataset.presets import build_building, preset_recipes
from envelope.results import FacadeEstimate
from envelope.truth import FacadeTruth
from envelope.wwr import wwr_from_areas
from metrics.score.facade_match import distance_to_outline_m, has_facade_geometry, match_facades
from neural3d.extract import facade_estimates
from neural3d.extraction.measure import measure_semantic_mesh
from neural3d.extraction.meshing import extract_mesh, label_vertices

TOL = 1e-9


@pytest.fixture(scope="module")
def l_shaped():
    """tiny_l_shaped: facades 2 (x = 6.26 m) and 4 (x = 1.09 m) both face +x."""
    (recipe,) = [r for r in preset_recipes("tiny") if r.id == "tiny_l_shaped"]
    return build_building(recipe).truth


def _estimate(i, normal, centre, window=3.0, gross=10.0):
    return FacadeEstimate(id=i, wwr=window / gross, window_area_m2=window,
                          facade_area_m2=gross, width_m=2.0, height_m=5.0,
                          normal=normal, centre_m=centre)


def test_distance_to_outline_closed_form():
    square = [[0, 0, 0], [0, 1, 0], [0, 1, 1], [0, 0, 1]]  # in the plane x = 0
    assert distance_to_outline_m([2.0, 0.5, 0.5], square) == pytest.approx(2.0, abs=TOL)
    assert distance_to_outline_m([-2.0, 3.0, 0.5], square) == pytest.approx(np.sqrt(8), abs=TOL)
    assert distance_to_outline_m([0.0, 0.25, 0.75], square) == pytest.approx(0.0, abs=TOL)
    with pytest.raises(ValueError, match="corners"):
        distance_to_outline_m([0, 0, 0], square[:2])
    with pytest.raises(ValueError, match="no area"):
        distance_to_outline_m([0, 0, 0], [[0, 0, 0], [1, 1, 1], [2, 2, 2]])


def test_parallel_walls_go_to_the_nearest_outline(l_shaped):
    estimates = (_estimate(1, (1.0, 0.0, 0.0), (1.2, 4.5, 5.0)),   # near facade 4
                 _estimate(2, (0.98, 0.2, 0.0), (6.1, -2.0, 5.0)))  # near facade 2, 11.5 deg off
    match = match_facades(estimates, l_shaped)
    assert [f.id for f in match.facades] == [1, 2, 3, 4, 5, 6]
    assert match.false_positives == () and match.out_of_scope == ()
    assert [f.id for f in match.facades if not f.missing] == [2, 4]
    assert match.facades[1] == replace(estimates[1], id=2)  # one estimate: figures unchanged
    assert match.facades[3] == replace(estimates[0], id=4)
    assert all(f.reason == "no estimated facade lies on this facade"
               for f in match.facades if f.missing)


def test_segments_merge_and_a_stray_estimate_is_a_false_positive(l_shaped):
    estimates = (_estimate(1, (0.0, -1.0, 0.0), (-3.0, -6.7, 5.0), window=2.0, gross=10.0),
                 _estimate(2, (0.0, -1.0, 0.0), (3.0, -6.8, 5.0), window=4.0, gross=30.0),
                 _estimate(3, (0.0, 0.0, 1.0), (0.0, 0.0, 10.6)))  # a roof, faces no facade
    match = match_facades(estimates, l_shaped)
    merged = match.facades[0]
    assert (merged.id, merged.missing) == (1, False)
    assert (merged.window_area_m2, merged.facade_area_m2) == (6.0, 40.0)
    assert merged.wwr == pytest.approx(wwr_from_areas(6.0, 34.0, 0.0), abs=TOL)
    assert (merged.width_m, merged.height_m) == (4.0, 5.0)
    assert merged.centre_m == pytest.approx((1.5, -6.775, 5.0), abs=TOL)  # area-weighted
    assert [(u.estimate.id, u.reason) for u in match.false_positives] == [
        (3, "estimated facade 3 faces no wall of the truth (normal within 45 degrees): a "
            "false positive")]


def test_merge_without_areas_is_missing_with_a_reason(l_shaped):
    a = _estimate(1, (0.0, -1.0, 0.0), (-3.0, -6.7, 5.0))
    b = replace(a, id=2, window_area_m2=None)
    merged = match_facades((a, b), l_shaped).facades[0]
    assert merged.missing and "not all have window and facade areas" in merged.reason


def test_truth_without_outlines_goes_by_normal(l_shaped):
    bare = replace(l_shaped, facade_outlines_m={})
    match = match_facades((_estimate(1, (0.6, -0.8, 0.0), (0.0, 0.0, 0.0)),), bare)
    # -y (facade 1) is 37 deg away, +x (facades 2 and 4) 53 deg: only facade 1 qualifies
    assert [f.id for f in match.facades if not f.missing] == [1]


@pytest.mark.slow
def test_curved_wall_segments_merge_into_one_facade():
    """A measured cylinder mesh (several segments) against a 64-facet curved truth facade."""
    def sdf(p):
        return cylinder_sdf(p, [0, 0], 5.0, 0.0, 10.0)

    v, f = extract_mesh(sdf, [-6, -6, -1], [6, 6, 11], voxel_size_m=0.15)
    m = measure_semantic_mesh(v, f, label_vertices(v, banded_labels(sdf, (3.0, 6.0))))
    estimates = facade_estimates(m)
    angles = np.linspace(0, 2 * np.pi, 65)
    outlines = [[[5 * np.cos(a0), 5 * np.sin(a0), 0], [5 * np.cos(a1), 5 * np.sin(a1), 0],
                 [5 * np.cos(a1), 5 * np.sin(a1), 10], [5 * np.cos(a0), 5 * np.sin(a0), 10]]
                for a0, a1 in zip(angles[:-1], angles[1:])]
    area = 2 * np.pi * 5 * 10
    wall = FacadeTruth(id=1, normal=(1.0, 0.0, 0.0), width_m=2 * np.pi * 5, height_m=10.0,
                       window_area_m2=0.3 * area, wall_area_m2=0.7 * area, door_area_m2=0.0,
                       facade_area_m2=area, wwr=0.3, curved=True)
    (recipe,) = [r for r in preset_recipes("tiny") if r.id == "tiny_skyscraper"]
    truth = replace(build_building(recipe).truth, facades=(wall,),
                    facade_outlines_m={1: outlines})
    match = match_facades(estimates, truth)
    assert len(estimates) > 1 and match.false_positives == ()
    (whole,) = match.facades
    assert whole.facade_area_m2 == pytest.approx(sum(e.facade_area_m2 for e in estimates),
                                                 rel=TOL)
    assert whole.wwr == pytest.approx(0.3, abs=0.01)
    assert whole.width_m == pytest.approx(2 * np.pi * 5, rel=0.02)  # area / height: arc length


def test_bad_input(l_shaped):
    located = _estimate(1, (1.0, 0.0, 0.0), (6.0, 0.0, 5.0))
    assert has_facade_geometry((located,)) and not has_facade_geometry(())
    assert not has_facade_geometry((located, replace(located, centre_m=None)))
    with pytest.raises(ValueError, match="no normal or centre_m"):
        match_facades((replace(located, normal=None),), l_shaped)
    with pytest.raises(ValueError, match="zero normal"):
        match_facades((replace(located, normal=(0.0, 0.0, 0.0)),), l_shaped)
