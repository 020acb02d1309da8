"""metrics.score.orientation_errors and the report's section: WWR error per orientation in
percentage
points and the share of facades within ±5 / ±10 pp, against errors worked out by hand.

The box (tests/export_box.py): true WWR N 0.2, E 0.3, S 0, W 2/15. Its ideal result: E 0.25
(-5 pp, exactly on the ±5 bound), S 0 (0 pp), W 0.15 (+5/3 pp), N not estimated (no error,
outside both bands). Its located result: E 0.28 (-2 pp), S 0, N and W not estimated.
"""

import contextlib
import io
from dataclasses import replace

import pytest
from export_box import box_truth, ideal_result, located_result
from metrics_helpers import make_benchmark

from metrics.compare import main as compare_main
from metrics.report.html_orientation import orientation_section
from metrics.report.report_data import read_table_records, table_records
from metrics.report.report_orientation import orientation_table
from metrics.report.tables import read_csv_rows, write_table
from metrics.score.aggregate import ALL_FAMILIES
from metrics.score.orientation_errors import (
    ORIENTATION_TABLE_NAME,
    orientation_errors,
    orientation_errors_of,
    summarise_orientations,
)


def _by_bin(rows):
    return {r.orientation: r for r in rows}


def test_errors_per_bin_of_a_result_on_truth_ids():
    rows = _by_bin(orientation_errors(ideal_result(), box_truth()))
    assert rows["E"].error_pp == pytest.approx(-5.0)
    assert (rows["E"].within_5pp, rows["E"].within_10pp) == (1, 1)  # the bound is inside
    assert rows["S"].wwr_true == 0.0 and rows["S"].wwr_est == 0.0 and rows["S"].error_pp == 0
    assert rows["W"].error_pp == pytest.approx(100 * (0.15 - 12 / 90))
    n = rows["N"]
    assert (n.facades, n.estimated, n.wwr_est, n.error_pp, n.within_10pp) == (1, 0, None,
                                                                              None, 0)
    assert n.wwr_true == pytest.approx(0.2)


def test_errors_per_bin_of_a_result_with_its_own_facades():
    rows = _by_bin(orientation_errors(located_result(), box_truth()))
    assert rows["E"].error_pp == pytest.approx(-2.0)
    assert rows["S"].error_pp == 0.0
    assert rows["W"].estimated == 0 and rows["N"].estimated == 0
    assert orientation_errors(located_result(), None) == ()


def test_summaries_pool_buildings_and_count_facades():
    a, b = box_truth("a"), replace(box_truth("b"), type="l_shaped")
    rows = orientation_errors_of([(ideal_result("a"), a), (replace(ideal_result("b"),
                                  facades=ideal_result("b").facades[:3] + (replace(
                                      ideal_result("b").facades[3], wwr=0.35, missing=False,
                                      window_area_m2=18.9, facade_area_m2=54.0),)), b)])
    summaries = {(s.family, s.orientation): s for s in summarise_orientations(rows)}
    north = summaries[(ALL_FAMILIES, "N")]  # a: not estimated; b: 0.35 vs 0.2 = +15 pp
    assert (north.buildings, north.facades) == (2, 2)
    assert north.abs_error_pp.mean == pytest.approx(15.0) and north.abs_error_pp.count == 1
    assert north.within_10pp_percent == 0.0
    east = summaries[(ALL_FAMILIES, "E")]
    assert east.abs_error_pp.mean == pytest.approx(5.0) and east.bias_pp.mean == pytest.approx(-5)
    assert east.within_5pp_percent == 100.0
    assert summaries[("l_shaped", "N")].buildings == 1
    table = orientation_table(list(summaries.values()))
    assert table.keys[:4] == ("family", "method", "protocol", "orientation")


@pytest.mark.slow
def test_compare_writes_the_table_and_the_report_shows_it(tmp_path):
    """metrics_helpers' benchmark: 2D-S on sky_a estimates facade 1 (+x, E) at 0.30 against
    0.25 (+5 pp) and facade 2 (+y, N) at 0.25 (0 pp); its other results have no facades."""
    data, results = make_benchmark(tmp_path)
    out = tmp_path / "out"
    with contextlib.redirect_stdout(io.StringIO()):
        assert compare_main(["--data", str(data), "--results", str(results), "--out", str(out),
                             "--views", "ideal", "--no-run"]) == 0
    rows = read_csv_rows((out / f"{ORIENTATION_TABLE_NAME}.csv").read_text())
    got = {(r["family"], r["method"], r["orientation"]): r for r in rows}
    east = got[("skyscraper", "2D-S", "E")]
    assert float(east["abs_error_pp_mean"]) == pytest.approx(5.0)
    assert float(east["within_5pp_percent"]) == 100.0
    assert float(got[("skyscraper", "2D-S", "N")]["abs_error_pp_mean"]) == pytest.approx(0.0)
    assert (out / f"{ORIENTATION_TABLE_NAME}.md").is_file()
    report = (out / "report.html").read_text()
    assert "WWR error per orientation" in report and 'id="orientation"' in report


def test_report_section_without_the_table_says_how_to_get_it(tmp_path):
    assert "rerun `python -m metrics.compare`" in orientation_section(None)
    table = orientation_table(summarise_orientations(orientation_errors(
        ideal_result(), box_truth())))
    write_table(table, tmp_path)
    html = orientation_section(table_records(table))
    assert html.count("<tr") == 1 + 8  # header + (skyscraper, all) x 4 bins
    assert "5.00 ± 0.00" in html and "chart-orientation" in html
    # the same section from the table in memory and read back from its CSV
    read_back = read_table_records((tmp_path / f"{ORIENTATION_TABLE_NAME}.csv").read_text())
    assert orientation_section(read_back) == html
