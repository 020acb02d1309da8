"""bench/neural3d_fixed_step.py on a small ring scene: its table, and its --json figures
against what the two steps must give (a buffer of every sample drops nothing and
evaluates every slot; a small one evaluates exactly its slots and drops the rest)."""

import json
import subprocess
import sys

import pytest
from neural3d_scene import write_ring_scene
from paths import REPO_ROOT

SAMPLES = 128 * 31  # the batch below: 128 rays x (16 + 16 - 1) sections


@pytest.mark.slow
def test_the_bench_times_both_steps(box_building, tmp_path):
    scene = write_ring_scene(box_building, tmp_path / "box", size_px=24, n_train=8, n_eval=0)
    out = tmp_path / "fixed.json"
    run = subprocess.run(
        [sys.executable, "bench/neural3d_fixed_step.py", "--scene", str(scene),
         "--buffer", "256", str(SAMPLES), "--warmup", "2", "--blocks", "2",
         "--block-steps", "2", "--threads", "1", "--set", "rays_per_batch=128",
         "--json", str(out)],
        cwd=REPO_ROOT, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    assert "| step | it/s (median) | time / today (median, range) |" in run.stdout
    today, small, every = json.loads(out.read_text())["variants"]
    assert [v["variant"] for v in (today, small, every)] == ["today", "fixed 256",
                                                             f"fixed {SAMPLES}"]
    assert today["ratio"] == 1.0 and all(v["it_per_s"] > 0 for v in (today, small, every))
    assert today["dropped_per_step"] == 0
    assert today["points_per_step"] == today["candidates_per_step"] <= SAMPLES
    assert every["points_per_step"] == SAMPLES and every["dropped_per_step"] == 0
    assert small["points_per_step"] == 256
    assert small["candidates_per_step"] > 256  # the first steps of a sphere: many heavy
    assert small["dropped_per_step"] == pytest.approx(small["candidates_per_step"] - 256)


@pytest.mark.slow
def test_a_folder_without_a_scene_is_refused(tmp_path):
    run = subprocess.run([sys.executable, "bench/neural3d_fixed_step.py", "--scene",
                          str(tmp_path)], cwd=REPO_ROOT, capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 2 and "not a scene folder" in run.stderr
