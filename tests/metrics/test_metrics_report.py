"""Tables 2 and 3 and the per-building CSV, built from hand-made rows."""

import pytest

from metrics.report.report import (
    per_building_table,
    read_building_errors_csv,
    table2_errors,
    table3_footprint_iou,
)
from metrics.report.tables import to_csv
from metrics.score.aggregate import aggregate_by_family
from metrics.score.errors import BuildingErrors, failed_building

ROWS = [
    BuildingErrors("a", "skyscraper", "2D-S", "ideal", wwr_est=0.3, wwr_true=0.25, wwr_ape=20.0,
                   window_ape=10.0, facade_ape=5.0, steps=1000),
    BuildingErrors("b", "skyscraper", "2D-S", "ideal", wwr_est=0.25, wwr_true=0.25, wwr_ape=0.0,
                   window_ape=0.0, facade_ape=5.0),
    BuildingErrors("a", "skyscraper", "neural3d", "train", wwr_ape=1.0, footprint_iou=0.9),
    failed_building("b", "skyscraper", "neural3d", "train", "RuntimeError: out of memory"),
]


def test_table2_rows_and_failure_notes():
    table = table2_errors(aggregate_by_family(ROWS))
    first = table.rows[0]
    assert first[:5] == ("skyscraper", "2D-S", "ideal", 2, 0)
    assert (first[5].mean, first[5].std) == (10.0, 10.0)
    assert (first[6].mean, first[7].mean) == (5.0, 5.0)
    assert table.notes == ("failed: skyscraper / neural3d / train: b: RuntimeError: out of memory",)


def test_table3_keeps_footprint_methods_only():
    groups = aggregate_by_family(ROWS)
    table = table3_footprint_iou(groups, footprint_methods=set())
    assert [r[:3] for r in table.rows] == [("skyscraper", "neural3d", "train"),
                                           ("all", "neural3d", "train")]
    assert table.rows[0][3:5] == (2, 1) and table.rows[0][5].mean == 0.9
    failed_only = aggregate_by_family([ROWS[3]])
    assert len(table3_footprint_iou(failed_only, {"neural3d"}).rows) == 2  # still listed
    assert table3_footprint_iou(failed_only, set()).rows == ()
    assert table3_footprint_iou(failed_only, set()).notes == ("no method estimates a footprint",)


def test_per_building_csv_round_trips(tmp_path):
    path = tmp_path / "per_building.csv"
    path.write_text(to_csv(per_building_table(ROWS), "a comment"))
    assert read_building_errors_csv(path) == ROWS


def test_per_building_csv_bad_input(tmp_path):
    with pytest.raises(ValueError, match="run `python -m metrics.compare` first"):
        read_building_errors_csv(tmp_path / "missing.csv")
    (tmp_path / "bad.csv").write_text("scene,family\na,b\n")
    with pytest.raises(ValueError, match="data row 1: not a per-building row"):
        read_building_errors_csv(tmp_path / "bad.csv")
