"""Comparisons on degraded inputs and the robustness study's table and plot."""

from __future__ import annotations

import contextlib
import io
import json

import pytest

from dataset.degrade.spec import parse_specs
from envelope.provenance import make_provenance, provenance_changes
from envelope.results import read_result
from metrics.compare import main
from metrics.report.report import read_building_errors_csv
from metrics.report.robustness_plot import RobustnessRow, plot_robustness
from metrics.robustness import RobustnessStudy, robustness_table, summarise
from metrics.run.degraded import CONFIG_KEY, with_degradation
from metrics.run.runner import folder_spec
from metrics.score.errors import BuildingErrors


def _row(scene: str, method: str, ape: float | None, status: str = "ok") -> BuildingErrors:
    return BuildingErrors(scene, "skyscraper", method, "ideal", status=status,  # type: ignore
                          wwr_ape=ape, window_ape=ape, facade_ape=ape)


def test_summarise_pools_buildings_and_counts_failures() -> None:
    rows = [_row("a", "2D-S", 2.0), _row("b", "2D-S", 4.0), _row("c", "2D-S", None, "failed"),
            _row("a", "2D-SS", 1.0)]
    got = {r.method: r for r in summarise(rows, "pose", 0.3)}
    assert got["2D-S"].wwr_ape == pytest.approx(3.0) and got["2D-S"].failed == 1
    assert got["2D-S"].buildings == 3 and got["2D-SS"].degradation == "pose"
    table = robustness_table(list(got.values()))
    assert [r[2] for r in table.rows] == ["2D-S", "2D-SS"]


def test_plot_has_one_panel_per_degradation(tmp_path) -> None:
    rows = (summarise([_row("a", "2D-S", 1.0)], "pose", 0.0)
            + summarise([_row("a", "2D-S", 3.0)], "pose", 1.0)
            + summarise([_row("a", "2D-S", 5.0)], "occluders", 2.0))
    paths = plot_robustness(rows, tmp_path / "robustness")
    assert all(p.stat().st_size > 0 for p in paths)
    with pytest.raises(ValueError):
        plot_robustness(summarise([_row("a", "2D-S", None, "failed")], "pose", 1.0),
                        tmp_path / "none")


def test_every_method_and_views_gets_a_curve(tmp_path, monkeypatch) -> None:
    """More curves than markers (both 2D methods on four protocols, neural3d on two): none is
    left out of the plot."""
    import metrics.report.robustness_plot as robustness_plot

    series = [(m, p) for m in ("2D-S", "2D-SS") for p in ("ideal", "multi", "train", "street")]
    series += [("neural3d", "train"), ("neural3d", "street")]
    rows = [RobustnessRow("pose", s, m, p, 1, 0, 1.0 + s, None, None)
            for m, p in series for s in (0.0, 1.0)]
    drawn = []
    monkeypatch.setattr(robustness_plot, "save_figure",
                        lambda fig, stem: drawn.append(fig) or [])
    plot_robustness(rows, tmp_path / "robustness")
    (ax,) = drawn[0].axes
    assert [line.get_label() for line in ax.get_lines()] == [f"{m} ({p})" for m, p in series]


def test_study_rejects_bad_levels() -> None:
    with pytest.raises(ValueError):
        RobustnessStudy(levels=(("mask_miss", (2.0,)),))
    with pytest.raises(ValueError):
        RobustnessStudy(heavy_levels="some")


def test_degraded_specs_carry_the_degradation_in_their_configs() -> None:
    spec = folder_spec("2D-S", ("ideal",), {"a": 1}, lambda d, p: None)
    (degraded,) = with_degradation([spec], parse_specs("pose:0.5"))
    record = [{"name": "pose", "severity": 0.5, "seed": 0}]
    assert degraded.config == {"a": 1, CONFIG_KEY: record}
    # A clean result is never reused for a degraded run, nor one of another severity.
    def record(config):
        return make_provenance(config, modules=("envelope.wwr",), inputs={})

    assert provenance_changes(record({"a": 1}), record(degraded.config))
    assert provenance_changes(record({"a": 1, CONFIG_KEY: [
        {"name": "pose", "severity": 1.0, "seed": 0}]}), record(degraded.config))


@pytest.mark.slow
def test_compare_degrade_runs_on_a_cached_copy_against_the_original_truth(tiny_benchmark,
                                                                          tmp_path) -> None:
    argv = ["--data", str(tiny_benchmark), "--methods", "2D-S", "--views", "ideal",
            "--results", str(tmp_path / "results"), "--out", str(tmp_path / "out")]
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(argv) == 0
        assert main([*argv, "--degrade", "mask_erode:2"]) == 0
    key = "mask_erode-2_seed0"
    clean = read_building_errors_csv(tmp_path / "out" / "per_building.csv")
    degraded = read_building_errors_csv(tmp_path / f"out-{key}" / "per_building.csv")
    assert [r.wwr_true for r in clean] == [r.wwr_true for r in degraded]
    # Eroded windows: less window area measured on every building.
    for a, b in zip(clean, degraded):
        assert b.window_est_m2 < a.window_est_m2
    assert (tiny_benchmark.with_name(f"{tiny_benchmark.name}-degraded") / key).is_dir()
    results = list((tmp_path / "results" / "degraded" / key).glob("*.json"))
    assert results and all(read_result(p).config[CONFIG_KEY][0]["name"] == "mask_erode"
                           for p in results)
    prov = json.loads((tmp_path / f"out-{key}" / "provenance.json").read_text())
    assert prov["methods"]["2D-S"]["config"][CONFIG_KEY][0]["severity"] == 2.0


def test_bad_degrade_is_one_line_error(tmp_path, capsys) -> None:
    assert main(["--data", str(tmp_path), "--degrade", "fog:1", "--no-run"]) == 2
    err = capsys.readouterr().err
    assert "unknown degradation" in err and len(err.strip().splitlines()) == 1
