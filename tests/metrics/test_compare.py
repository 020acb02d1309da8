"""`python -m metrics.compare` on a hand-made results folder reproduces the hand-computed tables."""

import contextlib
import io
import json
import math

import pytest
from metrics_helpers import make_benchmark

from metrics.compare import main
from metrics.report.report import read_building_errors_csv
from metrics.report.tables import read_csv_rows

TOL = 1e-9


@pytest.fixture(scope="module")
def compared(tmp_path_factory):
    """Run the CLI once (read-only) on the hand-made benchmark; returns (out folder, stdout)."""
    root = tmp_path_factory.mktemp("compare")
    data, results = make_benchmark(root)
    out = root / "out"
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(["--data", str(data), "--results", str(results), "--out", str(out),
                     "--views", "ideal,train", "--no-run"])
    assert code == 0
    return out, buf.getvalue()


# The hand-made results have no 2D train result, and --no-run computes none: the 2D methods'
# train runs (they declare train) fail with "no result file", one row per family and method.
NO_2D_TRAIN_ROWS = {(family, method, "train"): n
                    for family, n in (("skyscraper", 2), ("l_shaped", 1), ("all", 3))
                    for method in ("2D-S", "2D-SS")}


def _rows_by_key(path):
    rows = read_csv_rows(path.read_text())
    return {(r["family"], r["method"], r["protocol"]): r for r in rows}


@pytest.mark.slow
def test_table2_reproduces_the_hand_computed_errors(compared):
    out, _ = compared
    t2 = _rows_by_key(out / "table2_errors.csv")
    expected = {
        # (family, method, views): buildings, failed, (WWR mean, std), (window ...), (facade ...)
        ("skyscraper", "2D-S", "ideal"): (2, 0, (15, 5), (10, 10), (0, 0)),
        ("skyscraper", "2D-SS", "ideal"): (2, 0, (20, 20), (0, 0), (0, 0)),
        ("skyscraper", "neural3d", "train"): (2, 0, (0, 0), (0, 0), (0, 0)),
        ("l_shaped", "2D-S", "ideal"): (1, 0, (0, 0), (0, 0), (0, 0)),
        ("l_shaped", "2D-SS", "ideal"): (1, 1, None, None, None),
        ("l_shaped", "neural3d", "train"): (1, 1, None, None, None),
        ("all", "2D-S", "ideal"): (3, 0, (10, math.sqrt(200 / 3)), (20 / 3, math.sqrt(800 / 9)),
                                   (0, 0)),
    }
    for key, (n, failed, *errors) in expected.items():
        row = t2.pop(key)
        assert (int(row["buildings"]), int(row["failed"])) == (n, failed), key
        for name, stat in zip(("wwr_ape", "window_ape", "facade_ape"), errors):
            if stat is None:
                assert row[f"{name}_mean"] == row[f"{name}_std"] == "", key
            else:
                got = (float(row[f"{name}_mean"]), float(row[f"{name}_std"]))
                assert got == pytest.approx(stat, abs=TOL), (key, name)
    assert set(t2) == {("all", "2D-SS", "ideal"), ("all", "neural3d", "train"),
                       *NO_2D_TRAIN_ROWS}
    for key, n in NO_2D_TRAIN_ROWS.items():  # every 2D train run failed: no result file
        assert (int(t2[key]["buildings"]), int(t2[key]["failed"])) == (n, n), key


def test_table3_lists_footprint_methods_with_failures(compared):
    out, _ = compared
    t3 = _rows_by_key(out / "table3_footprint_iou.csv")
    assert set(t3) == {("skyscraper", "neural3d", "train"), ("l_shaped", "neural3d", "train"),
                       ("all", "neural3d", "train")}
    sky = t3[("skyscraper", "neural3d", "train")]
    assert (float(sky["footprint_iou_mean"]), float(sky["footprint_iou_std"])) == pytest.approx(
        (2 / 3, 1 / 3), abs=TOL)
    assert t3[("l_shaped", "neural3d", "train")]["failed"] == "1"


def test_failures_are_reported_with_reasons(compared):
    out, stdout = compared
    md = (out / "table2_errors.md").read_text()
    assert "failed: l_shaped / 2D-SS / ideal: ell_c: corrupt result file" in md
    assert "failed: l_shaped / neural3d / train: ell_c: no result file" in md
    assert "ell_c: corrupt result file" in stdout
    rows = read_building_errors_csv(out / "per_building.csv")
    failed = [(r.scene, r.method, r.protocol) for r in rows if r.status == "failed"]
    assert failed == [("ell_c", "2D-S", "train"), ("ell_c", "2D-SS", "ideal"),
                      ("ell_c", "2D-SS", "train"), ("ell_c", "neural3d", "train"),
                      ("sky_a", "2D-S", "train"), ("sky_a", "2D-SS", "train"),
                      ("sky_b", "2D-S", "train"), ("sky_b", "2D-SS", "train")]
    assert all(r.reason.startswith("no result file") for r in rows
               if r.status == "failed" and r.protocol == "train")


def test_stdout_has_both_tables(compared):
    _, stdout = compared
    assert "Absolute percentage error (%)" in stdout and "Footprint IoU" in stdout
    assert "15.00 ± 5.00" in stdout and "0.667 ± 0.333" in stdout


def test_every_output_records_its_provenance(compared):
    out, _ = compared
    prov = json.loads((out / "provenance.json").read_text())
    assert prov["code_version"] and prov["data"].endswith("data")
    assert set(prov["methods"]) == {"2D-S", "2D-SS", "neural3d"}
    assert len(prov["runs"]) == 15  # 3 scenes x (2D-S, 2D-SS on ideal and train; neural3d)
    for name in ("table2_errors.csv", "table3_footprint_iou.csv", "per_building.csv"):
        assert (out / name).read_text().startswith("# produced by `python -m metrics.compare")
    assert (out / "table2_errors.tex").read_text().startswith("% produced by")
    assert (out / "table2_errors.md").read_text().startswith("<!-- produced by")


def test_plots_footprints_and_pointers_are_written(compared):
    out, _ = compared
    for stem in ("errors_by_family", "wwr_scatter", "iou_per_building"):
        for ext in ("png", "pdf"):
            assert (out / "plots" / f"{stem}.{ext}").stat().st_size > 1000
    assert sorted(p.name for p in (out / "footprints").iterdir()) == [
        "sky_a__neural3d__train.geojson", "sky_b__neural3d__train.geojson"]
    assert json.loads((out / "neural3d_runs.json").read_text()) == {"runs": []}


def test_per_facade_rows(compared):
    out, _ = compared
    rows = read_csv_rows((out / "per_facade.csv").read_text())
    # failed runs (ell_c's corrupt file, the missing files) missed all of their facades
    missed = [(r["scene"], r["method"], r["protocol"], r["facade_id"]) for r in rows
              if r["kind"] == "missed"]
    failed_runs = [("ell_c", "2D-S", "train"), ("ell_c", "2D-SS", "ideal"),
                   ("ell_c", "2D-SS", "train"), ("ell_c", "neural3d", "train"),
                   *((s, m, "train") for s in ("sky_a", "sky_b") for m in ("2D-S", "2D-SS"))]
    assert missed == [(*run, f) for run in failed_runs for f in ("1", "2")]
    assert all(r["status"] == "failed" for r in rows if r["kind"] == "missed")
    matched = [r for r in rows if r["kind"] == "matched"]
    assert [(r["scene"], r["facade_id"]) for r in matched] == [("sky_a", "1"), ("sky_a", "2")]
    assert [float(r["wwr_ape"]) for r in matched] == pytest.approx([20.0, 0.0], abs=TOL)


@pytest.mark.parametrize(
    ("args", "message"),
    [(["--data", "/nonexistent/folder"], "data folder /nonexistent/folder does not exist"),
     (["--methods", "2D-S,magic"], "unknown method 'magic'"),
     (["--views", "sideways"], "unknown views 'sideways'"),
     (["--device", "tpu"], "unknown device 'tpu'"),
     (["--neural3d-max-minutes", "0"], "neural3d max minutes must be > 0"),
     (["--neural3d-steps", "-3"], "neural3d steps must be >= 1")],
)
def test_bad_input_is_one_line_and_exit_code_2(tmp_path, capsys, args, message):
    data, _ = make_benchmark(tmp_path)
    argv = args if args[0] == "--data" else ["--data", str(data), *args]
    assert main([*argv, "--out", str(tmp_path / "o"), "--no-run"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and message in err and "Traceback" not in err
    assert err.count("\n") == 1
    assert not (tmp_path / "o").exists()


def test_a_device_that_is_not_here_is_refused_when_something_would_run(tmp_path, capsys):
    data, _ = make_benchmark(tmp_path)
    assert main(["--data", str(data), "--device", "cuda:99", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "torch sees" in err and err.count("\n") == 1


@pytest.mark.slow
def test_no_run_reads_results_of_a_device_that_is_not_here(tmp_path):
    """Results made on a GPU machine are read and tabled on one without a GPU."""
    data, results = make_benchmark(tmp_path)
    argv = ["--data", str(data), "--results", str(results), "--out", str(tmp_path / "o"),
            "--no-run", "--device", "cuda:99"]
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        assert main(argv) == 0
    assert (tmp_path / "o" / "table2_errors.md").is_file()


@pytest.mark.slow
def test_runs_the_2d_methods_on_the_tiny_benchmark_then_reuses_them(tiny_benchmark, tmp_path):
    argv = ["--data", str(tiny_benchmark), "--methods", "2D-S,2D-SS", "--views", "ideal",
            "--results", str(tmp_path / "results"), "--out", str(tmp_path / "out")]
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(argv) == 0
    out = tmp_path / "out"
    rows = read_building_errors_csv(out / "per_building.csv")
    assert len(rows) == 6 and {r.status for r in rows} == {"ok"}
    # A sanity bound, not an accuracy claim: 96 px renders, every family.
    assert all(0 <= r.wwr_ape < 50 for r in rows), [(r.scene, r.method, r.wwr_ape) for r in rows]
    assert {r.family for r in rows} == {"skyscraper", "l_shaped", "realistic"}
    kinds = sorted(p.name.rsplit("__", 1)[1] for p in (out / "2dss_pipeline").iterdir())
    assert kinds == ["corners.png", "mask.png", "rectified.png"]
    prov = json.loads((out / "provenance.json").read_text())
    assert {r["status"] for r in prov["runs"]} == {"ran"}
    assert prov["methods"]["2D-SS"]["config"]  # the config the method ran with
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(argv) == 0
    prov = json.loads((out / "provenance.json").read_text())
    assert {r["status"] for r in prov["runs"]} == {"reused"}


@pytest.mark.slow
def test_a_second_comparison_leaves_no_stale_plot_or_footprint(tmp_path):
    data, results = make_benchmark(tmp_path)
    out = tmp_path / "out"
    base = ["--data", str(data), "--results", str(results), "--out", str(out), "--no-run",
            "--views", "ideal,train"]
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        assert main(base) == 0
        assert (out / "plots" / "iou_per_building.png").is_file()
        (out / "notes.txt").write_text("a user's file")
        assert main([*base, "--methods", "2D-S"]) == 0
    assert not (out / "plots" / "iou_per_building.png").exists()
    assert (out / "plots" / "wwr_scatter.png").is_file()
    assert list((out / "footprints").iterdir()) == []
    assert (out / "notes.txt").read_text() == "a user's file"  # the folder itself is kept
