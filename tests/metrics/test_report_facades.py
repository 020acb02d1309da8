"""metrics.report.report_facades: coverage, false positives and WWR points from per-facade rows,
hand-computed."""

import pytest

from metrics.report.report_facades import facade_scores_table
from metrics.score.aggregate import ALL_FAMILIES, Summary
from metrics.score.errors import FacadeErrors

TOL = 1e-9


def _rows(method, family="terraced", scene="a"):
    base = (scene, family, method, "street")
    return [
        FacadeErrors(*base, 1, wwr_est=0.30, wwr_true=0.27, facade_est_m2=40.0),  # 3 points
        FacadeErrors(*base, 2, wwr_est=0.10, wwr_true=0.18, facade_est_m2=20.0),  # 8 points
        FacadeErrors(*base, 3, wwr_est=0.50, wwr_true=0.20, facade_est_m2=10.0),  # 30 points
        FacadeErrors(*base, 4, status="failed", wwr_true=0.2, kind="missed"),
        FacadeErrors(*base, 0, status="failed", wwr_est=0.2, kind="false_positive",
                     facade_est_m2=12.5),
    ]


def test_hand_computed_scores_for_one_family():
    table = facade_scores_table(_rows("2D-SS"))
    (row,) = table.rows
    cells = dict(zip(table.keys, row))
    assert cells["family"] == ALL_FAMILIES and cells["facades"] == 4
    assert cells["coverage_pct"] == pytest.approx(75.0, abs=TOL)
    assert (cells["false_positives"], cells["false_positive_m2"]) == (1, 12.5)
    assert cells["mean_points"] == pytest.approx((3 + 8 + 30) / 3, abs=1e-6)
    assert cells["within_5_pct"] == pytest.approx(25.0, abs=TOL)   # 1 of all 4
    assert cells["within_10_pct"] == pytest.approx(50.0, abs=TOL)  # 2 of all 4
    assert cells["wwr_ape"] is None


def test_families_methods_and_the_building_error_beside():
    rows = _rows("2D-SS") + _rows("neural3d", family="detached", scene="b")
    wwr = Summary(4.0, 1.0, 2)

    class Group:  # the fields of GroupSummary the table reads
        family, method, protocol, wwr_ape = "detached", "neural3d", "street", wwr

    table = facade_scores_table(rows, [Group()])
    keys = [r[:3] for r in table.rows]
    assert keys == [("terraced", "2D-SS", "street"), ("detached", "neural3d", "street"),
                    (ALL_FAMILIES, "2D-SS", "street"), (ALL_FAMILIES, "neural3d", "street")]
    assert table.rows[1][-1] == wwr and table.rows[0][-1] is None
    assert all(r[3] == 1 for r in table.rows)  # one building each
