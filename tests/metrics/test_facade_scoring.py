"""metrics.score.facade_scoring: the one scoring rule. Every method's facades are paired with the
truth's (by id, or by geometry with covered and uncovered walls alike); an estimate on an
uncovered wall leaves the building's figures, a false positive stays in them, a covered
facade without an estimate is missed."""

from dataclasses import replace
from functools import lru_cache

import numpy as np
import pytest
from paths import FIXTURES

from dataset.importers.citygml.convert import import_citygml
from dataset.presets import build_building, preset_recipes
from envelope.results import FacadeEstimate, MethodResult
from envelope.wwr import ClassAreas
from metrics.score.errors import LEFT_OUT_FACADE_ID, building_errors, facade_errors, missed_facades
from metrics.score.facade_match import ON_WALL_MAX_DISTANCE_M
from metrics.score.facade_scoring import score_result

TOL = 1e-9


def _estimate(i, normal, centre, window, gross):
    return FacadeEstimate(id=i, wwr=window / gross if gross else None, window_area_m2=window,
                          facade_area_m2=gross, normal=tuple(float(x) for x in normal),
                          centre_m=tuple(float(x) for x in centre))


def _result(scene, estimates, identity="own"):
    window = sum(e.window_area_m2 for e in estimates)
    gross = sum(e.facade_area_m2 for e in estimates)
    return MethodResult(scene=scene, method="perfect", protocol="train", wwr=window / gross,
                        window_area_m2=window, facade_area_m2=gross, facades=tuple(estimates),
                        facade_identity=identity)


def _centre(outline):
    return np.asarray(outline, dtype=np.float64).mean(axis=0)


def _perfect_estimates(truth):
    """What a method that reconstructs every wall exactly reports: the truth's covered facades
    (their areas, normals and outline centres) and one wall-only facade per uncovered wall
    (its outline's normal and centre, 10 m² of wall)."""
    out = []
    for f in truth.facades:
        corners = np.concatenate([np.asarray(w) for w in truth.facade_outlines_m[f.id]])
        out.append(_estimate(len(out) + 1, f.normal, corners.mean(axis=0), f.window_area_m2,
                             f.facade_area_m2))
    for record, outline in zip(truth.extra["uncovered_facades"], truth.uncovered_outlines_m):
        out.append(_estimate(len(out) + 1, record["normal"], _centre(outline), 0.0, 10.0))
    return tuple(out)


@pytest.mark.parametrize("building_id", ["4018259", "4018133", "4018149b"])
def test_a_perfect_method_gets_the_covered_truth_on_real_buildings(building_id):
    """Real LoD3 buildings: every wall measured exactly, the back and party walls included;
    the walls the truth does not count leave the figures, which equal the truth's (1e-9)."""
    (building,) = import_citygml(FIXTURES / "citygml" / f"{building_id}.xml.xz")[:1]
    truth = building.truth
    assert not truth.counts_every_wall and truth.uncovered_outlines_m
    result = _result(building_id, _perfect_estimates(truth))
    assert result.facade_area_m2 > truth.facade_area_m2  # the uncounted walls
    scored = score_result(result, truth)
    assert scored.result.window_area_m2 == pytest.approx(truth.window_area_m2, rel=TOL)
    assert scored.result.facade_area_m2 == pytest.approx(truth.facade_area_m2, rel=TOL)
    assert scored.result.wwr == pytest.approx(truth.wwr, rel=TOL)
    assert len(scored.match.out_of_scope) == len(truth.uncovered_outlines_m)
    assert scored.match.false_positives == ()
    row = building_errors(result, truth)
    assert row.wwr_ape == pytest.approx(0.0, abs=1e-6) and "does not count" in row.reason
    rows = facade_errors(result, truth)
    assert [(f.facade_id, f.kind) for f in rows] == [(f.id, "matched") for f in truth.facades]
    assert all(f.wwr_points == pytest.approx(0.0, abs=1e-6) for f in rows)


@lru_cache(maxsize=1)
def _closed_form_case():
    """Real building 4018133 (three covered facades, three uncovered walls): facade A measured
    perfectly, a spurious facade 5 m in front of A, facade B and C missed, one estimate on
    an uncovered wall."""
    (building,) = import_citygml(FIXTURES / "citygml" / "4018133.xml.xz")[:1]
    truth = building.truth
    a = truth.facades[0]
    a_centre = _centre(truth.facade_outlines_m[a.id][0])
    perfect = _estimate(1, a.normal, a_centre, a.window_area_m2, a.facade_area_m2)
    spurious = _estimate(2, a.normal, a_centre + 5.0 * np.asarray(a.normal), 4.0, 20.0)
    record, outline = truth.extra["uncovered_facades"][0], truth.uncovered_outlines_m[0]
    on_uncovered = _estimate(3, record["normal"], _centre(outline), 2.0, 30.0)
    return truth, perfect, spurious, on_uncovered


def test_the_rule_on_a_closed_form_case_is_the_same_for_every_method():
    """One perfect facade, one spurious, two missed, one on an uncovered wall: coverage 1 of 3,
    false-positive area 20 m², the building charged A + the spurious facade, for a result
    that locates its own facades and for one that carries the truth's ids alike."""
    truth, perfect, spurious, on_uncovered = _closed_form_case()
    a = truth.facades[0]
    expected = ClassAreas(a.window_area_m2 + 4.0, a.facade_area_m2 + 20.0 - a.window_area_m2
                          - 4.0, 0.0)
    own = _result("x", (perfect, spurious, on_uncovered))
    by_id = _result("x", (replace(perfect, id=a.id), replace(spurious, id=99)),
                    identity="truth_id")
    for result, out_of_scope in ((own, 1), (by_id, 0)):
        scored = score_result(result, truth)
        assert len(scored.match.out_of_scope) == out_of_scope
        assert scored.result.facade_area_m2 == pytest.approx(expected.gross_m2, abs=TOL)
        assert scored.result.window_area_m2 == pytest.approx(expected.window_m2, abs=TOL)
        assert scored.result.wwr == pytest.approx(expected.wwr, abs=TOL)
        rows = facade_errors(result, truth)
        kinds = [(r.facade_id, r.kind) for r in rows]
        assert kinds == [(a.id, "matched"), (truth.facades[1].id, "missed"),
                         (truth.facades[2].id, "missed"), (LEFT_OUT_FACADE_ID, "false_positive")]
        assert rows[0].wwr_points == pytest.approx(0.0, abs=1e-9)
        assert rows[1].status == "failed" and rows[1].wwr_true == truth.facades[1].wwr
        assert rows[3].facade_est_m2 == 20.0 and rows[3].wwr_est == pytest.approx(0.2)
        row = building_errors(result, truth)
        assert row.facade_est_m2 == pytest.approx(expected.gross_m2, abs=TOL)
        assert row.wwr_ape == pytest.approx(100 * abs(expected.wwr - truth.wwr) / truth.wwr)


def test_the_distance_limit_separates_on_the_wall_from_a_false_positive():
    """An estimate 0.9 m in front of facade A is A's; one 1.1 m in front is a false positive."""
    truth, perfect, _, _ = _closed_form_case()
    normal = np.asarray(perfect.normal)
    for offset_m, kind in ((0.9, "matched"), (1.1, "false_positive")):
        moved = replace(perfect, centre_m=tuple(np.asarray(perfect.centre_m)
                                                + offset_m * normal))
        kinds = {r.kind for r in facade_errors(_result("x", (moved,)), truth)} - {"missed"}
        assert kinds == {kind}, (offset_m, ON_WALL_MAX_DISTANCE_M)


def test_everything_on_uncovered_walls_fails_the_figures():
    truth, _, _, on_uncovered = _closed_form_case()
    result = _result("x", (on_uncovered,))
    assert score_result(result, truth).result.wwr is None
    row = building_errors(result, truth)
    assert row.status == "failed" and "does not count" in row.reason


def test_an_old_scene_without_uncovered_outlines_fails_with_the_way_out():
    truth, perfect, _, _ = _closed_form_case()
    records = [{k: v for k, v in r.items() if k != "outline_m"}
               for r in truth.extra["uncovered_facades"]]
    old = replace(truth, extra={**truth.extra, "uncovered_facades": records})
    row = building_errors(_result("x", (perfect,)), old)
    assert row.status == "failed" and "regenerate" in row.reason


def test_against_a_truth_that_counts_every_wall_the_figures_are_the_results_own():
    """A procedural building: nothing is out of scope; an estimate 100 m away is a false
    positive whose areas stay in the building's figures."""
    (recipe,) = [r for r in preset_recipes("tiny") if r.id == "tiny_l_shaped"]
    truth = build_building(recipe).truth
    assert truth.counts_every_wall and truth.uncovered_outlines_m == ()
    far = _estimate(1, truth.facades[0].normal, (100.0, 100.0, 5.0), 3.0, 10.0)
    result = _result("x", (far,))
    assert score_result(result, truth).result == result
    assert building_errors(result, truth).facade_est_m2 == 10.0
    rows = facade_errors(result, truth)
    assert [r.kind for r in rows] == ["missed"] * len(truth.facades) + ["false_positive"]


def test_a_failed_run_missed_every_facade():
    truth, perfect, _, _ = _closed_form_case()
    failed = replace(_result("x", (perfect,)), wwr=None, window_area_m2=None,
                     facade_area_m2=None, facades=(), warnings=("no usable view",))
    rows = facade_errors(failed, truth)
    assert [(r.facade_id, r.kind, r.reason) for r in rows] == [
        (f.id, "missed", "no usable view") for f in truth.facades]
    assert missed_facades("x", "m", "street", None, "gone") == ()
