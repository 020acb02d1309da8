"""bench/neural3d_skips.py on a briefly trained ring scene: its table, its --json figures
within their ranges, the block-first refresh equal to every cell's on a trained field."""

import json
import subprocess
import sys

import pytest
from neural3d_scene import write_ring_scene
from paths import REPO_ROOT


@pytest.mark.slow
def test_the_skips_bench_measures_both_shortcuts(box_building, tmp_path):
    scene = write_ring_scene(box_building, tmp_path / "box", size_px=24, n_train=8, n_eval=0)
    out = tmp_path / "skips.json"
    run = subprocess.run(
        [sys.executable, "bench/neural3d_skips.py", "--scene", str(scene), "--steps", "60",
         "--check", "0", "60", "--rays", "256", "--threads", "1", "--json", str(out),
         "--set", "occupancy_start=0", "--set", "occupancy_every=20"],
        cwd=REPO_ROOT, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    assert "| step | rays hit | heavy share |" in run.stdout
    record = json.loads(out.read_text())
    assert [c["step"] for c in record["checks"]] == [0, 60]
    for check in record["checks"]:
        assert 0 < check["heavy_share"] <= 1 and check["rays_hit"] > 0
        loose, tight = check["guess 1e-06"], check["guess 0.0001"]
        assert loose["kept_share"] >= tight["kept_share"]  # a lower threshold keeps more
        assert loose["recall"] >= tight["recall"] and 0.9 <= tight["recall"] <= 1
        assert 0 <= tight["weight_dropped_share"] < 0.05
    assert len(record["refreshes"]) == 3  # steps 0, 20, 40
    assert all(r["cells_differing"] == 0 and 0 < r["query_share"] < 1
               for r in record["refreshes"])


def test_a_folder_without_a_scene_is_refused(tmp_path):
    run = subprocess.run([sys.executable, "bench/neural3d_skips.py", "--scene", str(tmp_path)],
                         cwd=REPO_ROOT, capture_output=True, text=True, timeout=120)
    assert run.returncode == 2 and "not a scene folder" in run.stderr
