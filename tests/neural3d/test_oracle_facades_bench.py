"""bench/oracle_facades.py: the summary of scored buildings and the before/after tables."""

import pytest

from bench.oracle_facades import building_table, compare_table, summary


def _building(scene, family, wwr_ape, iou, facades):
    return {"scene": scene, "family": family, "estimated_facades": len(facades),
            "building": {"wwr_ape": wwr_ape, "window_ape": 2 * wwr_ape, "facade_ape": 1.0,
                         "footprint_iou": iou},
            "facades": [{"id": i + 1, "kind": kind, "wwr_points": points, "facade_ape": ape,
                         "facade_est_m2": 10.0} for i, (kind, points, ape) in enumerate(facades)]}


BEFORE = {"code_version": "a", "buildings": [
    _building("box", "skyscraper", 4.0, 0.98, [("matched", 1.0, 2.0), ("missed", None, None)]),
    _building("ell", "l_shaped", 2.0, 0.99, [("matched", 6.0, 4.0), ("false_positive", None,
                                                                      None)])]}


def test_summary_counts_facades_and_averages_the_matched_ones():
    s = summary(BEFORE["buildings"])
    assert s["buildings"] == 2 and s["truth facades"] == 3
    assert s["missed"] == 1 and s["false positives"] == 1
    assert s["WWR APE %"] == pytest.approx(3.0) and s["IoU"] == pytest.approx(0.985)
    assert s["facade WWR error pt"] == pytest.approx(3.5)
    assert s["within 5 pt %"] == pytest.approx(50.0)  # 1.0 within 5 points, 6.0 not
    assert s["facade area APE %"] == pytest.approx(3.0)


def test_tables_show_what_moved_and_only_the_buildings_that_moved():
    after = {"code_version": "b", "buildings": [
        BEFORE["buildings"][0],
        _building("ell", "l_shaped", 1.5, 0.99, [("matched", 6.0, 4.0)])]}
    table = compare_table(BEFORE, after)
    assert "| l_shaped | 1 | 2.000 → 1.500 |" in table
    assert "| skyscraper | 1 | 4.000 |" in table
    rows = building_table(BEFORE, after).splitlines()[2:]
    assert len(rows) == 1 and rows[0].startswith("| ell | 2.000 → 1.500 |")
