"""SIGINT and SIGKILL at random (seeded) points of generate, train and compare, then a rerun:
nothing half-written is ever taken for finished, and the rerun completes."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from paths import REPO_ROOT

from envelope.results import read_result
from envelope.scenes.scene import read_scene

ROOT = REPO_ROOT


def _interrupt(argv: list[str], ready: Path, sig: int, delay_s: float) -> tuple[int, str]:
    """Start ``python -m argv``, wait until ``ready`` exists, wait ``delay_s``, send ``sig``."""
    env = {**os.environ, "PYTHONPATH": str(ROOT), "OMP_NUM_THREADS": "1"}
    proc = subprocess.Popen([sys.executable, "-m", *map(str, argv)], cwd=ROOT, env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while not ready.exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    time.sleep(delay_s)
    if proc.poll() is None:
        proc.send_signal(sig)
    _, err = proc.communicate(timeout=120)
    return proc.returncode, err


def _rerun(argv: list[str]) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "OMP_NUM_THREADS": "1"}
    return subprocess.run([sys.executable, "-m", *map(str, argv)], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=300)


def _check_interrupted(code: int, err: str, sig: int, message: str) -> None:
    """Finished (0), or stopped by the signal: one line for SIGINT, nothing to say for SIGKILL."""
    assert "Traceback" not in err
    if code == 0:
        return
    if sig == signal.SIGINT:
        assert code == 130 and message in err
    else:
        assert code == -signal.SIGKILL


SIGNAL_CASES = [(sig, seed) for sig in (signal.SIGINT, signal.SIGKILL) for seed in (0,)]


@pytest.mark.slow
@pytest.mark.parametrize("sig, seed", SIGNAL_CASES)
def test_generate_interrupted_then_rerun(sig, seed, tmp_path):
    out = tmp_path / "out"
    argv = ["dataset.generate", "--mesh", ROOT / "dataset/examples/example_bim.ply", "--out", out,
            "--resolution", "48", "--views", "6", "--quiet"]
    delay = np.random.default_rng([seed, sig]).uniform(0.0, 0.6)
    code, err = _interrupt(argv, out, sig, delay)
    _check_interrupted(code, err, sig, "interrupted: finished scenes are kept")
    if (out / "example_bim").exists():
        read_scene(out / "example_bim")  # a folder with the final name is always finished
    assert sig == signal.SIGKILL or not list(out.glob(".*.partial"))  # only SIGKILL leaves one
    done = _rerun(argv)
    assert done.returncode == 0, done.stderr
    read_scene(out / "example_bim")  # complete and valid
    assert not list(out.glob(".*.partial"))


@pytest.mark.slow
@pytest.mark.parametrize("sig, seed", SIGNAL_CASES)
def test_train_interrupted_then_resumed(sig, seed, clean_scene, tmp_path):
    from neural3d.field.checkpoint import read_checkpoint

    runs = tmp_path / "runs"
    argv = ["neural3d.train", "--scene", clean_scene, "--preset", "tiny", "--iterations", "20",
            "--out", runs]
    delay = np.random.default_rng([seed, sig, 1]).uniform(0.0, 1.0)
    code, err = _interrupt(argv, runs / clean_scene.name / "log.csv", sig, delay)  # step 10+
    _check_interrupted(code, err, sig, "interrupted")
    run = runs / clean_scene.name
    resumable = (run / "checkpoint.pt").is_file()
    if sig == signal.SIGINT and code == 130:  # Ctrl-C in training leaves a checkpoint
        assert ("checkpoint saved" in err) == resumable, err
    done = _rerun(argv + (["--resume"] if resumable else []))
    assert done.returncode == 0, done.stderr
    import torch

    assert int(read_checkpoint(run / "checkpoint.pt", torch.device("cpu"))["step"]) == 20
    assert (run / "log.csv").read_text().splitlines()[-1].startswith("20,")


@pytest.mark.slow
@pytest.mark.parametrize("sig, seed", SIGNAL_CASES)
def test_compare_interrupted_then_rerun(sig, seed, clean_scene, tmp_path):
    bench, results = tmp_path / "bench", tmp_path / "results"
    for name in ("box_a", "box_b"):
        shutil.copytree(clean_scene, bench / name)
    argv = ["metrics.compare", "--data", bench, "--methods", "2D-S,2D-SS", "--results", results,
            "--out", tmp_path / "cmp"]
    delay = np.random.default_rng([seed, sig, 2]).uniform(0.0, 0.5)
    code, err = _interrupt(argv, results, sig, delay)
    _check_interrupted(code, err, sig, "interrupted: finished results are kept")
    for path in results.glob("*.json"):
        read_result(path)  # every result file on disk is whole
    assert sig == signal.SIGKILL or not list(results.glob(".*.tmp"))
    done = _rerun(argv)
    assert done.returncode == 0, done.stderr
    # scenes x methods x the default views (ideal, multi, train)
    assert len([read_result(p) for p in results.glob("*.json")]) == 2 * 2 * 3
    assert (tmp_path / "cmp" / "provenance.json").is_file()
