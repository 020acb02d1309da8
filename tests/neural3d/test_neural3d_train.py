"""Training on a tiny rendered box: losses fall, the level set fits, resume matches, errors."""

import csv
import json
from dataclasses import replace

import numpy as np
import pytest
import torch
from conftest import BOX_SIZE_M
from neural3d_scene import write_ring_scene
from paths import REPO_ROOT

from envelope.scenes.scene import read_method_input
from neural3d.config import preset_config
from neural3d.field.checkpoint import read_checkpoint
from neural3d.field.trained import load_trained_field
from neural3d.train import main, train
from neural3d.training.step import lr_factor

CPU = torch.device("cpu")
SHORT = replace(preset_config("tiny"), iterations=100, eval_every=50, checkpoint_every=50)
# Median |SDF| on the true box surface after SHORT training: measured 0.4-0.6 m on this
# 20 x 12 x 9 m box (32 px images, voxel-ish 0.3 m grid); bounded at 1.0 m (5 % of its length).
SURFACE_TOL_M = 1.0


@pytest.fixture(scope="module")
def scene(box_building, tmp_path_factory):
    return write_ring_scene(box_building, tmp_path_factory.mktemp("n3d") / "box", size_px=32,
                            n_train=16, n_eval=2)


@pytest.fixture(scope="module")
def short_run(scene, tmp_path_factory):
    return train(read_method_input(scene), SHORT, tmp_path_factory.mktemp("runs"), device=CPU)


def box_surface_points(n, seed=0):
    sx, sy, sz = BOX_SIZE_M
    rng = np.random.default_rng(seed)
    u, v = rng.random(n), rng.random(n)
    face = rng.integers(0, 5, n)
    x = np.where(face == 2, -sx / 2, np.where(face == 3, sx / 2, (u - 0.5) * sx))
    y = np.where(face == 0, -sy / 2, np.where(face == 1, sy / 2,
                 np.where(face == 4, (v - 0.5) * sy, (u - 0.5) * sy)))
    z = np.where(face == 4, sz, v * sz)
    return torch.tensor(np.stack([x, y, z], 1), dtype=torch.float32)


@pytest.mark.slow
def test_short_training_lowers_every_loss(short_run):
    with (short_run / "log.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert int(rows[-1]["step"]) == SHORT.iterations
    for key in ("loss", "rgb", "eikonal", "semantic", "mask"):
        first = float(rows[0][key])
        last = np.mean([float(r[key]) for r in rows[-3:]])
        assert last < first, f"{key}: {first} -> {last}"
    evals = json.loads((short_run / "eval.json").read_text())["evaluations"]
    assert [e["step"] for e in evals] == [50, 100]
    assert evals[-1]["semantic_accuracy"] > 0.8


@pytest.mark.slow
def test_zero_level_set_fits_the_box(short_run):
    field = load_trained_field(short_run, device=CPU)
    sdf = field.sdf_m(box_surface_points(1000))
    print("median |sdf| on the box surface (m):", float(sdf.abs().median()))
    assert sdf.abs().median() < SURFACE_TOL_M, sdf.abs().median()
    sx, sy, sz = BOX_SIZE_M
    assert field.sdf_m(torch.tensor([[0.0, 0.0, sz / 2]])) < 0
    outside = torch.tensor([[sx / 2 + 3, 0, sz / 2], [0, -sy / 2 - 3, sz / 2]])
    assert (field.sdf_m(outside) > 0).all()


@pytest.fixture
def one_thread():
    """Multi-threaded CPU reductions add floats in a varying order; one thread removes that."""
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(threads)


def _interrupted_and_resumed(scene, tmp_path):
    config = replace(preset_config("tiny"), iterations=6, rays_per_batch=32, eval_every=3,
                     checkpoint_every=100)
    straight = train(read_method_input(scene), config, tmp_path / "a", device=CPU)

    def interrupt(step, field):
        raise KeyboardInterrupt  # as Ctrl-C would, after step 3

    with pytest.raises(KeyboardInterrupt):
        train(read_method_input(scene), config, tmp_path / "b", device=CPU, callback=interrupt)
    assert read_checkpoint(tmp_path / "b" / "box" / "checkpoint.pt", CPU)["step"] == 3
    resumed = train(read_method_input(scene), config, tmp_path / "b", device=CPU, resume=True)
    return (read_checkpoint(straight / "checkpoint.pt", CPU),
            read_checkpoint(resumed / "checkpoint.pt", CPU))


@pytest.mark.slow
def test_interrupted_training_resumes_from_its_checkpoint(scene, tmp_path, one_thread):
    a, b = _interrupted_and_resumed(scene, tmp_path)
    assert a["step"] == b["step"] == 6
    assert a["field"].keys() == b["field"].keys()


@pytest.mark.slow
def test_resume_matches_uninterrupted_run(scene, tmp_path, one_thread):
    a, b = _interrupted_and_resumed(scene, tmp_path)
    for key, value in a["field"].items():
        diff = (value - b["field"][key]).abs().max()
        assert torch.allclose(value, b["field"][key], atol=1e-6), (key, diff)


@pytest.mark.slow
def test_callback_stops_early(scene, tmp_path):
    config = replace(preset_config("tiny"), iterations=50, rays_per_batch=16, eval_every=2)
    seen = []
    run = train(read_method_input(scene), config, tmp_path, device=CPU,
                callback=lambda s, f: seen.append(s) or True)
    assert seen == [2]
    assert read_checkpoint(run / "checkpoint.pt", CPU)["step"] == 2


def test_lr_schedule_warmup_then_cosine():
    c = replace(preset_config("tiny"), iterations=110, warmup=10, lr_final_factor=0.05)
    assert lr_factor(0, c) == pytest.approx(0.1)
    assert lr_factor(10, c) == pytest.approx(1.0)
    assert lr_factor(60, c) == pytest.approx(0.525)
    assert lr_factor(110, c) == pytest.approx(0.05)


def _edit_transforms(scene_dir, edit):
    path = scene_dir / "transforms.json"
    meta = json.loads(path.read_text())
    edit(meta)
    path.write_text(json.dumps(meta))


def test_scene_errors(scene, tmp_path):
    import shutil

    copy = tmp_path / "copy"
    shutil.copytree(scene, copy)
    _edit_transforms(copy, lambda m: [f.update(split="eval") for f in m["frames"]])
    with pytest.raises(ValueError, match="no 'train' frames"):
        train(read_method_input(copy), SHORT, tmp_path / "runs", device=CPU)
    _edit_transforms(copy, lambda m: [f.update(split="train") for f in m["frames"]])
    _edit_transforms(copy, lambda m: m.update(w=40))
    with pytest.raises(ValueError, match="is 32x32 but transforms.json says 40x32"):
        train(read_method_input(copy), SHORT, tmp_path / "runs", device=CPU)
    with pytest.raises(ValueError, match="unknown device"):
        train(read_method_input(scene), SHORT, tmp_path / "runs", device="tpu-9")
    with pytest.raises(ValueError, match="cannot resume"):
        train(read_method_input(scene), SHORT, tmp_path / "fresh", device=CPU, resume=True)


def test_cli_reports_errors_in_one_line(tmp_path, capsys):
    assert main(["--scene", str(tmp_path / "nowhere"), "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error:") and err.count("\n") == 1
    if not torch.cuda.is_available():
        assert main(["--scene", str(tmp_path), "--device", "cuda"]) == 2
        assert "CUDA is not available" in capsys.readouterr().err


@pytest.mark.slow
def test_mlp_backbone_and_finite_difference_normals_train(scene, tmp_path):
    tiny = preset_config("tiny")
    model = replace(tiny.model, backbone="mlp", mlp_hidden=64, mlp_layers=4, mlp_skip=2,
                    normals="finite_difference")
    config = replace(tiny, model=model, iterations=3, rays_per_batch=16, eval_every=3)
    run = train(read_method_input(scene), config, tmp_path, device=CPU)
    field = load_trained_field(run, device=CPU)
    assert torch.isfinite(field.sdf_m(torch.zeros(4, 3))).all()


def test_train_step_is_the_only_training_step():
    """bench/neural3d.py calls neural3d.training.step.train_step; no loss/backward of its own."""

    bench = (REPO_ROOT / "bench" / "neural3d.py").read_text()
    assert "train_step(" in bench
    for copy in ("total_loss", ".backward(", "render_rays", "torch.optim.Adam"):
        assert copy not in bench, f"bench/neural3d.py has its own {copy}"


@pytest.mark.slow
def test_sigterm_saves_a_checkpoint_like_ctrl_c(scene, tmp_path):
    """The CLI run is killed with SIGTERM mid-training; its checkpoint is there to resume."""
    import os
    import signal
    import subprocess
    import sys
    import time

    root = REPO_ROOT
    env = {**os.environ, "PYTHONPATH": str(root), "OMP_NUM_THREADS": "1"}
    proc = subprocess.Popen(
        [sys.executable, "-m", "neural3d.train", "--scene", str(scene), "--preset", "tiny",
         "--iterations", "100000", "--out", str(tmp_path)],
        env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    log = tmp_path / "box" / "log.csv"
    deadline = time.monotonic() + 120
    while not (log.is_file() and len(log.read_text().splitlines()) > 2):  # >= 20 steps done
        assert proc.poll() is None and time.monotonic() < deadline, proc.stderr.read()
        time.sleep(0.2)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130 and "checkpoint saved" in err
    assert read_checkpoint(tmp_path / "box" / "checkpoint.pt", CPU)["step"] >= 20


@pytest.mark.slow
def test_training_with_occupancy_grid_refreshes_and_checkpoints_it(scene, tmp_path):
    config = replace(preset_config("tiny"), iterations=6, rays_per_batch=32, eval_every=6,
                     checkpoint_every=6, occupancy_resolution=16, occupancy_start=2,
                     occupancy_every=2)
    run = train(read_method_input(scene), config, tmp_path, device=CPU)
    state = read_checkpoint(run / "checkpoint.pt", CPU)
    occupied = state["occupancy"]
    assert occupied.dtype == torch.bool and 0 < occupied.float().mean() < 1  # refreshed


def test_update_ema_is_the_exponential_average():
    from neural3d.training.step import update_ema

    average, field = torch.nn.Linear(2, 1), torch.nn.Linear(2, 1)
    with torch.no_grad():
        for p in average.parameters():
            p.fill_(0.0)
        for p in field.parameters():
            p.fill_(1.0)
    for _ in range(3):
        update_ema(average, field, 0.5)
    assert torch.allclose(average.weight, torch.full((1, 2), 0.875))  # 1 - 0.5^3


@pytest.mark.slow
def test_training_with_ema_checkpoints_and_loads_the_averaged_field(scene, tmp_path):
    config = replace(preset_config("tiny"), iterations=4, rays_per_batch=16, eval_every=4,
                     checkpoint_every=4, ema_decay=0.5)
    seen = []
    run = train(read_method_input(scene), config, tmp_path, device=CPU,
                callback=lambda s, f: seen.append(f.field.state_dict()["log_inv_s"].item()))
    state = read_checkpoint(run / "checkpoint.pt", CPU)
    assert state["ema"].keys() == state["field"].keys()
    table = "sdf_net.encoding.grid.table"
    assert not torch.equal(state["ema"][table], state["field"][table])
    loaded = load_trained_field(run, device=CPU).field.state_dict()
    assert torch.equal(loaded[table], state["ema"][table])
    assert seen == [state["ema"]["log_inv_s"].item()]  # the callback measured the average


@pytest.mark.slow
def test_each_evaluation_keeps_a_snapshot_of_the_measured_field(short_run):
    from neural3d.field.checkpoint import snapshot_path, snapshot_steps

    assert snapshot_steps(short_run) == [50, 100]
    final = read_checkpoint(short_run / "checkpoint.pt", CPU)["field"]
    last = read_checkpoint(snapshot_path(short_run, 100), CPU)["field"]
    assert all(torch.equal(final[k], last[k]) for k in final)
    points = box_surface_points(200)
    at_end = load_trained_field(short_run, device=CPU)
    assert torch.equal(load_trained_field(short_run, device=CPU, step=100).sdf_m(points),
                       at_end.sdf_m(points))
    halfway = load_trained_field(short_run, device=CPU, step=50).sdf_m(points)
    assert not torch.equal(halfway, at_end.sdf_m(points))
    with pytest.raises(ValueError, match=r"no snapshot of step 70; it has \[50, 100\]"):
        load_trained_field(short_run, device=CPU, step=70)
