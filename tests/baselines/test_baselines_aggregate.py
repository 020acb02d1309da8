"""baselines.aggregate: combining views, missing facades, the building result."""

import pytest

from baselines.aggregate import building_result, combine_values, missing_facade
from envelope.results import FacadeEstimate


def _result(facades, weighting="alpha"):
    return building_result(scene="s", method="2D-SS", protocol="multi", facades=facades,
                           weighting=weighting, config={"a": 1}, wall_time_s=0.5,
                           warnings=["w0"])


def test_combine_mean_and_median_skip_none():
    assert combine_values([1.0, None, 2.0, 6.0], "mean") == pytest.approx(3.0)
    assert combine_values([1.0, None, 2.0, 6.0], "median") == pytest.approx(2.0)
    assert combine_values([None], "mean") is None
    with pytest.raises(ValueError, match="unknown combination"):
        combine_values([1.0], "max")


def test_missing_facade_keeps_distinct_reasons():
    f = missing_facade(3, ["cut off", "cut off", "no depth"])
    assert f.missing and f.wwr is None and f.id == 3
    assert f.reason == "no usable view: cut off; no depth"


def test_building_sums_areas_and_counts_missing_facades():
    facades = [
        FacadeEstimate(2, 0.4, 40.0, 100.0, 10.0, 10.0, views_used=1),
        missing_facade(3, ["cut off"]),
        FacadeEstimate(1, 0.2, 40.0, 200.0, 20.0, 10.0, views_used=2),
    ]
    r = _result(facades)
    assert r.wwr == pytest.approx((0.2 * 2 + 0.4 * 1) / 3)  # alpha weights 2 and 1
    assert r.window_area_m2 == pytest.approx(80.0)
    assert r.facade_area_m2 == pytest.approx(300.0)
    assert [f.id for f in r.facades] == [1, 2, 3]
    assert r.warnings[0] == "w0"
    assert "1 of 3 facades missing (ids 3)" in r.warnings[1]
    assert r.config == {"a": 1} and r.code_version


def test_areas_unavailable_when_a_facade_has_no_scale():
    facades = [FacadeEstimate(1, 0.2, None, None), FacadeEstimate(2, 0.4, 4.0, 10.0)]
    r = _result(facades, weighting="equal")
    assert r.wwr == pytest.approx(0.3)
    assert r.window_area_m2 is None and r.facade_area_m2 is None
    assert any("areas unavailable" in w for w in r.warnings)


def test_nothing_left_is_an_error_listing_the_reasons():
    with pytest.raises(ValueError, match="nothing left to measure: facade 3: no usable view: cut"):
        _result([missing_facade(3, ["cut off"])])


def test_no_facade_at_all_reports_the_warnings():
    with pytest.raises(ValueError, match="nothing left to measure: w0"):
        _result([])
