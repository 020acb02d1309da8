"""Seeds averaged per building, errors against the visible truth, the claims' tables."""

from dataclasses import replace

import pytest
from metrics_helpers import make_result, make_truth

from envelope.results import read_result, result_filename, write_result
from envelope.wwr import ClassAreas
from metrics.report.paper_tables import PAPER_TABLE2_LABEL, paper_table2, paper_table3
from metrics.report.report_paper import paper_table2_comparison, paper_table3_comparison
from metrics.report.report_seeds import seed_spread_table
from metrics.report.report_visible import table2_visible_errors
from metrics.report.tables import format_cell, read_csv_rows, read_summary, to_csv
from metrics.run.compare_args import parse_seeds
from metrics.score.aggregate import aggregate_by_family, seed_mean, seed_sd
from metrics.score.errors import BuildingErrors, building_errors, failed_building


def _run(scene, seed, wwr_ape, iou=0.9):
    return BuildingErrors(scene, "skyscraper", "neural3d", "train", wwr_ape=wwr_ape,
                          footprint_iou=iou, seed=seed)


def test_seeds_are_averaged_per_building_before_the_family_mean():
    rows = [_run("a", s, e) for s, e in ((0, 1.0), (1, 2.0), (2, 3.0))]
    rows += [_run("b", s, 3.0) for s in (0, 1, 2)]
    rows += [replace(failed_building("c", "skyscraper", "neural3d", "train", "diverged"),
                     seed=s) for s in (0, 1, 2)]
    (group, _) = aggregate_by_family(rows)
    assert (group.buildings, group.failed, group.seeds) == (3, 1, "3")
    assert group.wwr_ape.mean == pytest.approx(2.5) and group.wwr_ape.count == 2
    assert group.wwr_ape.std == pytest.approx(0.5)
    assert group.wwr_seed_sd.mean == pytest.approx(0.5)  # seed SDs 1.0 and 0.0
    assert group.iou_seed_sd.mean == pytest.approx(0.0)
    assert "c (seed 2): diverged" in group.reasons
    table = seed_spread_table([group])
    assert table is not None and table.rows[0][4] == "3"


def test_single_seed_helpers_and_groups_without_seeds():
    assert seed_mean([None, 2.0, 4.0]) == 3.0 and seed_mean([None]) is None
    assert seed_sd([1.0]) is None and seed_sd([1.0, 3.0]) == pytest.approx(2 ** 0.5)
    (group, _) = aggregate_by_family([BuildingErrors("a", "l_shaped", "2D-S", "ideal",
                                                     wwr_ape=1.0)])
    assert group.seeds is None and seed_spread_table([group]) is None


def test_errors_against_the_visible_truth():
    truth = make_truth("a")
    # Facade 1 shows 4 m² less wall and 2 m² less window than it has: 8 / 12 / 0 -> 8 + ...
    f1 = replace(truth.facades[0], visible_window_area_m2=8.0, visible_wall_area_m2=26.0,
                 visible_door_area_m2=0.0)
    f2 = replace(truth.facades[1], visible_window_area_m2=5.0, visible_wall_area_m2=13.0,
                 visible_door_area_m2=2.0)
    truth = replace(truth, facades=(f1, f2))
    assert truth.visible_areas_m2() == ClassAreas(13.0, 39.0, 2.0)  # gross 54, WWR 13 / 54
    result = make_result("a", "2D-S", "ideal", 13.0 / 54.0, window_m2=13.0, facade_m2=54.0)
    row = building_errors(result, truth)
    assert row.wwr_ape_visible == pytest.approx(0.0, abs=1e-12)
    assert row.window_ape_visible == pytest.approx(0.0) and row.facade_ape_visible == 0.0
    assert row.facade_ape == pytest.approx(100 * 6 / 60)  # against the full 60 m²
    assert building_errors(result, make_truth("a")).wwr_ape_visible is None  # no visible truth
    (group, _) = aggregate_by_family([row])
    table = table2_visible_errors([group])
    assert table.rows[0][5].mean == pytest.approx(0.0, abs=1e-12)  # WWR, visible
    assert table.rows[0][8].mean == pytest.approx(10.0)  # facade, full


def test_results_of_several_seeds_keep_a_file_each(tmp_path):
    result = make_result("a", "neural3d", "train", 0.25)
    assert result_filename("a", "neural3d", "train") == "a__neural3d__train.json"
    assert result_filename("a", "neural3d", "train", 0) == "a__neural3d__train.json"
    assert result_filename("a", "neural3d", "train", 2) == "a__neural3d__train__seed2.json"
    paths = {write_result(tmp_path, replace(result, seed=s)) for s in (0, 1, 2)}
    assert len(paths) == 3
    assert read_result(tmp_path / "a__neural3d__train__seed1.json").seed == 1
    assert parse_seeds("0, 1,2") == (0, 1, 2)
    for bad in ("0,0", "-1", "x", ""):
        with pytest.raises(ValueError, match="--seeds"):
            parse_seeds(bad)


def test_paper_figures_sit_beside_ours_where_the_paper_has_the_row():
    assert paper_table2("realistic", "BuildNet3D", "train")["wwr_ape"].mean == 3.5
    assert paper_table2("l_shaped", "2D-SS", "multi")["facade_ape"].std == 0.5
    assert paper_table2("all", "2D-S", "ideal") is None  # the paper pools no families
    assert paper_table3("skyscraper", "BuildNet3D", "train").mean == 0.960
    assert paper_table3("skyscraper", None, "train") is None  # a method the paper has not
    assert paper_table3("skyscraper", "2D-S", "ideal") is None
    rows = [BuildingErrors(s, "realistic", "neural3d", "train", wwr_ape=e, window_ape=e,
                           facade_ape=1.0, footprint_iou=0.97) for s, e in (("a", 2.0), ("b", 4.0))]
    groups = aggregate_by_family(rows)
    names = {"neural3d": "BuildNet3D"}  # what neural3d's Method.paper_name says
    t2, t3 = paper_table2_comparison(groups, names), paper_table3_comparison(groups, names)
    assert paper_table2_comparison(groups, {}).rows == ()  # no method known to the paper
    assert len(t2.rows) == 1 and len(t3.rows) == 1  # the pooled row has no paper figure
    assert format_cell(t2.rows[0][6], 2) == "3.50 ± 2.20"
    assert format_cell(t2.rows[0][5], 2) == "3.00 ± 1.00 [2.00, 4.00]"
    assert format_cell(t3.rows[0][6], 3) == "0.971"
    assert PAPER_TABLE2_LABEL in t2.columns[6] and any("100,000" in n for n in t2.notes)
    csv_row = read_csv_rows(to_csv(t2))[0]
    assert read_summary(csv_row, "wwr_ape") == replace(t2.rows[0][5], count=0)


def test_a_2d_row_on_the_orbit_views_has_no_paper_figure():
    """The paper ran 2D-S and 2D-SS on ideal and multi views only: their `train` rows (own
    facades on the orbit) stand alone, their ideal rows keep the paper's figures."""
    assert paper_table2("l_shaped", "2D-SS", "train") is None
    assert paper_table2("l_shaped", "2D-S", "train") is None
    rows = [BuildingErrors("a", "l_shaped", "2D-SS", protocol, wwr_ape=1.0, window_ape=1.0,
                           facade_ape=1.0) for protocol in ("ideal", "multi", "train")]
    t2 = paper_table2_comparison(aggregate_by_family(rows), {"2D-SS": "2D-SS"})
    assert [r[2] for r in t2.rows] == ["ideal", "multi"]
    assert format_cell(t2.rows[1][6], 2) == "8.00 ± 0.70"  # the paper's multi WWR error


def test_specs_differing_by_seed_run_and_are_reused_side_by_side(tmp_path):
    from dataclasses import dataclass

    from envelope.scenes.scene import find_scene_folders
    from envelope.truth import write_building
    from metrics.run.runner import folder_spec, run_missing

    @dataclass(frozen=True)
    class Seeded:
        seed: int

    write_building(tmp_path / "data" / "a" / "building.json", make_truth("a"))
    scenes = find_scene_folders(tmp_path / "data")
    calls = []

    def run(scene_dir, protocol, seed):
        calls.append(seed)
        return replace(make_result("a", "fake", protocol, 0.25 + seed / 100),
                       config={"seed": seed})

    specs = [folder_spec("fake", ("train",), Seeded(s), lambda d, p, s=s: run(d, p, s))
             for s in (0, 1)]
    out = run_missing(scenes, specs, tmp_path / "results", log=lambda _: None)
    assert [(o.status, o.result.seed) for o in out] == [("ran", 0), ("ran", 1)]
    assert sorted(p.name for p in (tmp_path / "results").iterdir()) == [
        "a__fake__train.json", "a__fake__train__seed1.json"]
    again = run_missing(scenes, specs, tmp_path / "results", log=lambda _: None)
    assert [o.status for o in again] == ["reused", "reused"] and calls == [0, 1]
    assert again[1].result.wwr == pytest.approx(0.26)


def test_claims_tables_leave_out_tables_without_rows():
    from metrics.comparison import claims_tables

    rows = [BuildingErrors(s, "l_shaped", "2D-S", "ideal", wwr_ape=e) for s, e in (("a", 1.0),
                                                                                  ("b", 2.0))]
    names = [t.name for t in claims_tables(aggregate_by_family(rows), {"2D-S": "2D-S"})]
    assert names == ["table2_visible", "paper_table2"]  # no seeds, no footprint in the paper


def test_report_sections_show_the_visible_table_with_its_intervals(tmp_path):
    from metrics.report.html_claims import claims_sections
    from metrics.report.html_report import table2_html, table3_html
    from metrics.report.report_data import read_table_records, table_records

    rows = [BuildingErrors(s, "realistic", "neural3d", "train", wwr_ape=e, footprint_iou=0.97,
                           wwr_ape_visible=e / 2) for s, e in (("a", 2.0), ("b", 4.0))]
    groups = aggregate_by_family(rows)
    (tmp_path / "table2_visible.csv").write_text(to_csv(table2_visible_errors(groups)))
    visible = read_table_records((tmp_path / "table2_visible.csv").read_text())
    html = claims_sections({"table2_visible": visible})
    assert "visible facade" in html and "1.50 ± 0.50 [1.00, 2.00]" in html
    assert "seed" not in html.lower()  # no seed table given
    assert claims_sections({"table2_visible": table_records(table2_visible_errors(groups))}) \
        == html  # in memory as read back
    from metrics.report.report import table2_errors, table3_footprint_iou

    names = {"neural3d": "BuildNet3D"}
    tables = (paper_table2_comparison(groups, names), paper_table3_comparison(groups, names),
              table2_errors(groups), table3_footprint_iou(groups, {"neural3d"}))
    in_memory = [table_records(t) for t in tables]
    read_back = [read_table_records(to_csv(t)) for t in tables]
    for paper2, paper3, table2, table3 in (in_memory, read_back):
        t2 = table2_html(table2, paper2)
        assert "3.00 ± 1.00 [2.00, 4.00]" in t2 and "3.50 ± 2.20" in t2  # ours, the paper's
        t3 = table3_html(table3, paper3)
        assert "BuildNet3D paper, Table 3" in t3 and "0.971" in t3
    assert table2_html(*in_memory[2::-2]) == table2_html(*read_back[2::-2])
    assert table3_html(in_memory[3], in_memory[1]) == table3_html(read_back[3], read_back[1])
