"""bench/neural3d_stages.py on a real (briefly) trained run: its table, its --json file, and
--compare-to that file finding no difference, then the one difference put into it."""

import json
import subprocess
import sys
from dataclasses import replace

import pytest
import torch
from neural3d_scene import write_ring_scene
from paths import REPO_ROOT

from envelope.scenes.scene import read_method_input
from neural3d.config import preset_config
from neural3d.method import RUNS_FOLDER
from neural3d.train import train

ROOT = REPO_ROOT


def _bench(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "bench/neural3d_stages.py", *args], cwd=ROOT,
                          capture_output=True, text=True, timeout=900)


@pytest.mark.slow
def test_the_stage_bench_checks_its_own_figures_float_for_float(box_building, tmp_path):
    scene = write_ring_scene(box_building, tmp_path / "box", size_px=24, n_train=8, n_eval=0)
    config = replace(preset_config("tiny"), iterations=4, eval_every=1000, checkpoint_every=1000)
    train(read_method_input(scene), config, tmp_path / "results" / RUNS_FOLDER,
          device=torch.device("cpu"))
    saved = tmp_path / "before.json"
    args = ("--results", str(tmp_path / "results"), "--resolution", "24", "--threads", "1",
            "--without", "concave_corner_fill")
    first = _bench(*args, "--json", str(saved))
    assert first.returncode == 0, first.stderr
    assert "| all | box |" in first.stdout and "| -concave_corner_fill | box |" in first.stdout
    record = json.loads(saved.read_text())
    (building,) = record["buildings"]
    assert set(building["sets"]) == {"all", "-concave_corner_fill"}
    assert building["mesh"]["faces"] > 0 and len(building["mesh"]["sha256"]) == 64

    again = _bench(*args, "--compare-to", str(saved))
    assert again.returncode == 0, again.stdout + again.stderr
    assert "2 stage-set results, 0 difference(s)" in again.stdout

    building["sets"]["all"]["result"]["facade_area_m2"] += 1e-9
    changed = tmp_path / "changed.json"
    changed.write_text(json.dumps(record))
    differs = _bench(*args, "--compare-to", str(changed))
    assert differs.returncode == 1
    assert "1 difference(s)" in differs.stdout and "box all .facade_area_m2" in differs.stdout

    missing = _bench(*args, "--compare-to", str(tmp_path / "nowhere.json"))
    assert missing.returncode == 2 and "--compare-to" in missing.stderr
