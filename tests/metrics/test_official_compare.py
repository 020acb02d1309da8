"""metrics.compare --data on scenes imported from both official layouts (the Blender
generator's own output, tests/fixtures/buildnet3d_generator; the BlenderProc layout written
by test_blenderproc's writer): 2D-S, 2D-SS and neural3d (tiny budget: the run, not its
accuracy, is checked here) all finish."""

from __future__ import annotations

import contextlib
import io

import pytest
from blenderproc_output import write_blenderproc_output
from paths import FIXTURES

from dataset.generate import main as generate_main


@pytest.mark.slow
def test_metrics_compare_runs_every_method_on_imported_scenes(box_building, tmp_path):
    from metrics.compare import main as compare_main
    from metrics.report.report import read_building_errors_csv
    from metrics.report.tables import read_csv_rows

    write_blenderproc_output(tmp_path / "bproc" / "house", box_building, "generator")
    data = tmp_path / "scenes"
    with contextlib.redirect_stdout(io.StringIO()):
        for src in (FIXTURES / "buildnet3d_generator" / "images/building0", tmp_path / "bproc"):
            assert generate_main(["--buildnet3d", str(src), "--out", str(data)]) == 0
    argv = ["--data", str(data), "--methods", "2D-S,2D-SS,neural3d", "--views", "ideal,train",
            "--neural3d-preset", "tiny", "--neural3d-steps", "30",
            "--neural3d-resolution", "32", "--neural3d-threads", "2",
            "--results", str(tmp_path / "results"), "--out", str(tmp_path / "out")]
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        assert compare_main(argv) == 0
    # Imported layouts may carry no truth: those are not scored, their estimates are listed.
    with_truth = {d.name for d in data.iterdir() if (d / "building.json").is_file()}
    scored = {(r.scene, r.method, r.status)
              for r in read_building_errors_csv(tmp_path / "out" / "per_building.csv")
              } if with_truth else set()
    estimated = {(r["scene"], r["method"], r["status"]) for r in read_csv_rows(
        (tmp_path / "out" / "estimates.csv").read_text())}
    every = {(scene, method, "ok") for scene in ("building0", "house")
             for method in ("2D-S", "2D-SS", "neural3d")}
    assert scored == {r for r in every if r[0] in with_truth}
    assert estimated == every and with_truth != {"building0", "house"}
