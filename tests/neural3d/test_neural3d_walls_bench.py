"""bench/neural3d_walls.py on a real (briefly) trained run: its tables, its --json file and
its refusals."""

import json
import subprocess
import sys
from dataclasses import replace

import pytest
import torch
from neural3d_scene import write_ring_scene
from paths import REPO_ROOT

from envelope.scenes.scene import read_method_input
from envelope.truth import write_building
from neural3d.config import preset_config
from neural3d.extraction.extract_config import ExtractConfig
from neural3d.method import RUNS_FOLDER
from neural3d.train import train


def _bench(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "bench/neural3d_walls.py", *args], cwd=REPO_ROOT,
                          capture_output=True, text=True, timeout=600)


@pytest.mark.slow
def test_the_walls_bench_tables_the_contour_and_each_setting(box_building, tmp_path):
    scene = write_ring_scene(box_building, tmp_path / "box", size_px=24, n_train=8, n_eval=0)
    write_building(scene / "building.json", box_building.truth)  # the truth to compare with
    config = replace(preset_config("tiny"), iterations=4, eval_every=1000, checkpoint_every=1000)
    train(read_method_input(scene), config, tmp_path / "results" / RUNS_FOLDER,
          device=torch.device("cpu"))
    out = tmp_path / "walls.json"
    done = _bench("--results", str(tmp_path / "results"), "--resolution", "24",
                  "--tolerances", "0.1", "0.2", "--min-walls", "1", "--threads", "1",
                  "--json", str(out))
    assert done.returncode == 0, done.stderr
    assert "| building | family | contour | 0.1/1 | 0.2/1 |" in done.stdout
    assert "| imported (1) | mean |" in done.stdout and "| all (1) | mean |" in done.stdout
    (building,) = json.loads(out.read_text())["buildings"]
    assert building["scene"] == "box" and building["family"] == "imported"
    assert set(building["iou"]) == {"contour", "0.1/1", "0.2/1"}
    assert all(0.0 < v <= 1.0 for v in building["iou"].values())

    default = _bench("--results", str(tmp_path / "results"), "--resolution", "24",
                     "--threads", "1")
    pair = f"{ExtractConfig.footprint_wall_tolerance_m:g}/{ExtractConfig.footprint_min_wall_m:g}"
    assert default.returncode == 0 and f"| contour | {pair} |" in default.stdout

    refused = _bench("--results", str(tmp_path / "results"), "--tolerances", "0")
    assert refused.returncode == 2 and "must be > 0" in refused.stderr
    nothing = _bench("--results", str(tmp_path / "nowhere"))
    assert nothing.returncode == 2 and "no trained runs" in nothing.stderr

    (scene / "building.json").unlink()
    no_truth = _bench("--results", str(tmp_path / "results"), "--resolution", "24")
    assert no_truth.returncode == 2 and "no truth footprint" in no_truth.stderr
