"""Error measures: absolute percentage error, footprint IoU, per-building and per-facade rows."""

import math
from dataclasses import replace

import pytest
from metrics_helpers import make_result, make_truth
from shapely.geometry import MultiPolygon, Point, Polygon, box

from envelope.results import FacadeEstimate
from metrics.score.errors import (
    absolute_percentage_error,
    building_errors,
    facade_errors,
    footprint_iou,
)

TOL = 1e-12  # every case below is exact in binary floating point up to rounding


def test_ape_hand_computed():
    assert absolute_percentage_error(0.30, 0.25) == pytest.approx(20.0, abs=TOL)
    assert absolute_percentage_error(0.20, 0.25) == pytest.approx(20.0, abs=TOL)
    assert absolute_percentage_error(7.0, 7.0) == 0.0
    assert absolute_percentage_error(0.0, 4.0) == 100.0


@pytest.mark.parametrize(
    ("estimate", "truth", "message"),
    [(0.1, 0.0, "positive true value"), (0.1, -1.0, "positive true value"),
     (math.nan, 0.2, "finite"), (0.1, math.inf, "finite")],
)
def test_ape_bad_input(estimate, truth, message):
    with pytest.raises(ValueError, match=message):
        absolute_percentage_error(estimate, truth)


def test_iou_identical_disjoint_nested_shifted():
    square = box(0, 0, 10, 10)
    assert footprint_iou(square, box(0, 0, 10, 10)) == pytest.approx(1.0, abs=TOL)
    assert footprint_iou(square, box(20, 0, 30, 10)) == 0.0
    assert footprint_iou(square, box(2, 2, 7, 7)) == pytest.approx(0.25, abs=TOL)
    assert footprint_iou(square, box(5, 0, 15, 10)) == pytest.approx(1 / 3, abs=TOL)


def test_iou_with_hole_and_multipolygon():
    ring = Polygon(box(0, 0, 10, 10).exterior.coords, [box(4, 4, 6, 6).exterior.coords])
    assert footprint_iou(ring, box(0, 0, 10, 10)) == pytest.approx(96 / 100, abs=TOL)
    two = MultiPolygon([box(0, 0, 1, 1), box(2, 0, 3, 1)])
    assert footprint_iou(two, box(0, 0, 3, 1)) == pytest.approx(2 / 3, abs=TOL)


def test_iou_repairs_a_self_touching_ring():
    bow_tie = Polygon([(0, 0), (2, 2), (2, 0), (0, 2)])  # invalid: two triangles of 1 m²
    assert footprint_iou(bow_tie, box(0, 0, 2, 2)) == pytest.approx(0.5, abs=1e-9)


def test_iou_bad_input():
    with pytest.raises(ValueError, match="first footprint has no area"):
        footprint_iou(Polygon(), box(0, 0, 1, 1))
    with pytest.raises(ValueError, match="second footprint must be a shapely"):
        footprint_iou(box(0, 0, 1, 1), Point(0, 0))


def test_building_errors_hand_computed():
    truth = make_truth("a")
    result = make_result("a", "neural3d", "train", 0.30, window_m2=18.0, facade_m2=45.0,
                         footprint_shift_m=5.0)
    row = building_errors(result, truth)
    assert (row.status, row.family, row.reason) == ("ok", "skyscraper", "")
    assert row.wwr_ape == pytest.approx(20.0, abs=TOL)
    assert row.window_ape == pytest.approx(20.0, abs=TOL)  # 18 vs 15 m²
    assert row.facade_ape == pytest.approx(25.0, abs=TOL)  # 45 vs 60 m²
    assert row.footprint_iou == pytest.approx(1 / 3, abs=TOL)
    assert (row.wwr_true, row.window_true_m2, row.facade_true_m2) == (0.25, 15.0, 60.0)


def test_building_errors_without_areas_footprint_or_truth():
    row = building_errors(make_result("a", "2D-S", "ideal", 0.25), make_truth("a"))
    assert row.wwr_ape == 0.0
    assert row.window_ape is None and row.facade_ape is None and row.footprint_iou is None
    no_truth = building_errors(make_result("a", "2D-S", "ideal", 0.25), None)
    assert (no_truth.family, no_truth.wwr_est, no_truth.wwr_ape) == ("unknown", 0.25, None)


def test_building_without_wwr_is_failed_with_its_warnings():
    result = replace(make_result("a", "2D-SS", "multi", None),
                     warnings=("view 3: no facade pixels", "facade 2: no usable view"))
    row = building_errors(result, make_truth("a"))
    assert row.status == "failed"
    assert row.reason == "view 3: no facade pixels; facade 2: no usable view"
    assert row.wwr_ape is None


def test_malformed_footprint_gives_no_iou_and_a_reason():
    result = replace(make_result("a", "neural3d", "train", 0.25),
                     footprint={"type": "Point", "coordinates": [0, 0]})
    row = building_errors(result, make_truth("a"))
    assert row.status == "ok" and row.footprint_iou is None
    assert "footprint: footprint must be a GeoJSON Polygon" in row.reason


def test_zero_true_wwr_gives_no_ape_and_a_reason():
    truth = replace(make_truth("a"), wwr=0.0)
    row = building_errors(make_result("a", "2D-S", "ideal", 0.1), truth)
    assert row.wwr_ape is None and "WWR: the percentage error needs" in row.reason


def test_facade_errors_hand_computed():
    result = make_result("a", "2D-S", "ideal", 0.28, facade_wwrs=(0.3, 0.25))
    f1, f2 = facade_errors(result, make_truth("a"))
    # Facade 1: WWR 0.3 vs 0.25, window 12 vs 10 m², facade 40 vs 40 m².
    assert (f1.facade_id, f1.wwr_ape, f1.window_ape, f1.facade_ape) == pytest.approx(
        (1, 20.0, 20.0, 0.0), abs=TOL)
    # Facade 2: WWR 0.25 vs 0.25, window 10 vs 5 m², facade 40 vs 20 m².
    assert (f2.facade_id, f2.wwr_ape, f2.window_ape, f2.facade_ape) == pytest.approx(
        (2, 0.0, 100.0, 100.0), abs=TOL)


def test_facade_errors_missing_unknown_and_unmatched_protocol():
    result = make_result("a", "2D-SS", "multi", 0.25, facade_wwrs=(0.25, 0.25, 0.25))
    facades = (replace(result.facades[0], wwr=None, missing=True, reason="no usable view"),
               *result.facades[1:])
    rows = facade_errors(replace(result, facades=facades), make_truth("a"))
    assert [(r.facade_id, r.status, r.reason) for r in rows] == [
        (1, "failed", "no usable view"), (2, "ok", ""),
        (0, "failed", "estimated facade 3: no such facade in the truth")]
    assert [r.kind for r in rows] == ["missed", "matched", "false_positive"]
    # Facades numbered by the method itself and without normal/centre cannot be matched.
    assert facade_errors(replace(result, facade_identity="geometry"), make_truth("a")) == ()


def test_neural3d_facades_are_matched_to_the_truth_by_normal_and_centre():
    """make_truth: facade 1 faces +x (40 m², WWR 0.25), facade 2 faces +y (20 m², WWR 0.25)."""
    result = make_result("a", "neural3d", "train", 0.25)
    own = (  # the method's ids: two halves of facade 1, one facing down, none on facade 2
        FacadeEstimate(id=1, wwr=0.3, window_area_m2=6.0, facade_area_m2=20.0,
                       normal=(1.0, 0.0, 0.0), centre_m=(10.0, 2.0, 2.0)),
        FacadeEstimate(id=2, wwr=0.2, window_area_m2=4.0, facade_area_m2=20.0,
                       normal=(0.9, 0.1, 0.0), centre_m=(10.0, 7.0, 2.0)),
        FacadeEstimate(id=3, wwr=0.5, window_area_m2=1.0, facade_area_m2=2.0,
                       normal=(0.0, 0.0, -1.0), centre_m=(5.0, 5.0, 0.0)),
    )
    rows = facade_errors(replace(result, facades=own), make_truth("a"))
    assert [(r.facade_id, r.status) for r in rows] == [(1, "ok"), (2, "failed"), (0, "failed")]
    assert rows[0].wwr_est == pytest.approx(10.0 / 40.0, abs=TOL)  # (6 + 4) / (20 + 20)
    assert (rows[0].wwr_ape, rows[0].window_ape, rows[0].facade_ape) == pytest.approx(
        (0.0, 0.0, 0.0), abs=TOL)
    assert rows[1].reason == "no estimated facade lies on this facade"
    assert "estimated facade 3 faces no wall of the truth" in rows[2].reason
    # without normal and centre the method's own ids mean nothing to the truth: no rows
    assert facade_errors(replace(result, facades=own[:2] + (replace(own[2], normal=None),)),
                         make_truth("a")) == ()
    assert facade_errors(make_result("a", "neural3d", "train", 0.25, facade_wwrs=(0.3, 0.25)),
                         make_truth("a")) == ()
    assert facade_errors(replace(result, facades=own), None) == ()
    bad = replace(result, facades=(replace(own[0], normal=(0.0, 0.0, 0.0)),))
    (row,) = facade_errors(bad, make_truth("a"))
    assert row.status == "failed" and "zero normal" in row.reason
