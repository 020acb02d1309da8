"""bench/neural3d_gpu_table.sh (a street of neural3d trainings at once) and
bench/neural3d_gpu_check.sh (the GPU figures in one pass), tried on the CPU: usage without
arguments, the step budget and extra options passed through to metrics.compare, the log's
last line."""

import re
import subprocess
from pathlib import Path

import pytest

from envelope.results import read_result

ROOT = Path(__file__).resolve().parents[2]
TABLE = ROOT / "bench" / "neural3d_gpu_table.sh"
CHECK = ROOT / "bench" / "neural3d_gpu_check.sh"


@pytest.mark.parametrize("script", [TABLE, CHECK])
def test_without_arguments_prints_its_usage_and_exits_2(script):
    done = subprocess.run(["bash", str(script)], capture_output=True, text=True, timeout=30)
    assert done.returncode == 2
    assert f"bash bench/{script.name}" in done.stdout
    assert "#" not in done.stdout  # the comment block, without its markers


def test_a_missing_data_folder_is_refused(tmp_path):
    done = subprocess.run(["bash", str(TABLE), str(tmp_path / "nope"), str(tmp_path / "r"),
                           str(tmp_path / "c")], capture_output=True, text=True, timeout=30)
    assert done.returncode == 2 and "is not a folder of scene folders" in done.stderr


@pytest.mark.slow
def test_trains_every_scene_at_the_steps_and_options_given(tiny_benchmark, tmp_path):
    """Two at once on the CPU (JOBS=2, DEVICE=cpu): 20 steps of the tiny preset at marching
    cubes 24 for each of the three buildings, the options after DEVICE reaching compare."""
    results, out = tmp_path / "results", tmp_path / "compare"
    done = subprocess.run(
        ["bash", str(TABLE), str(tiny_benchmark), str(results), str(out), "2", "20", "cpu",
         "--neural3d-preset", "tiny", "--neural3d-resolution", "24"],
        capture_output=True, text=True, timeout=600, cwd=ROOT)
    assert done.returncode == 0, done.stdout[-3000:]
    last = Path(f"{out}.log").read_text().strip().splitlines()[-1]
    assert re.fullmatch(r"wall \d+ s, exit code 0", last), last
    runs = [read_result(p) for p in sorted(results.glob("*__neural3d__train.json"))]
    assert len(runs) == 3
    for run in runs:
        assert run.steps == 20
        assert run.config["budget"]["preset"] == "tiny"
        assert run.config["resolution"] == 24 and run.config["budget"]["threads"] == 1
