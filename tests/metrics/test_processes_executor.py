"""The processes executor: heavy runs in processes of their own, as many at once as their
reservations fit, give the same results as the local executor; a run whose process dies is a
failed run alone; Ctrl-C stops the trainings with their checkpoints saved and whole result
files only; neural3d reserves its threads on CPU and a share of the GPU on CUDA.
"""

import os
import re
import signal
import subprocess
import sys
import threading
import time
from dataclasses import asdict, replace
from functools import partial
from pathlib import Path

import pytest

from envelope.progress import progress_bar
from envelope.results import read_result
from envelope.scenes.scene import find_scene_folders
from metrics.run.executors import make_executor
from metrics.run.methods import method_specs
from metrics.run.runner import run_missing
from neural3d.method import METHOD_NEURAL3D, Neural3dBudget, record_config, reserve


def _quiet(_message):
    pass


def _dies_on_first_scene(scene_dir, protocol):
    """2D-S, except that the process dies on tiny_l_shaped (as under the OOM killer)."""
    if scene_dir.name == "tiny_l_shaped":
        os._exit(3)
    return method_specs(("2D-S",), ("ideal",), scene_dir.parent)[0].run(scene_dir, protocol)


def _reserve(cpus, config):
    return cpus, 0.0


def _heavy_2ds(tmp_path, cpus=1.0, **spec_fields):
    """2D-S on the ideal views, declared heavy, reserving ``cpus`` cores a run."""
    spec = method_specs(("2D-S",), ("ideal",), tmp_path)[0]
    method = replace(spec.method, heavy=True, reserve=partial(_reserve, cpus))
    return replace(spec, method=method, **spec_fields)


def _2ds_noting_its_process(folder, scene_dir, protocol):
    """2D-S, writing the id of the process it ran in into ``folder``."""
    Path(folder, f"{scene_dir.name}.pid").write_text(str(os.getpid()))
    return method_specs(("2D-S",), ("ideal",), scene_dir.parent)[0].run(scene_dir, protocol)


def _2ds_after_a_counted_loop(scene_dir, protocol):
    """2D-S after a loop of three steps with a progress bar, as a training has."""
    bar = progress_bar(total=3, desc=f"fake training {scene_dir.name}")
    for _ in range(3):
        bar.update()
    bar.close()
    return method_specs(("2D-S",), ("ideal",), scene_dir.parent)[0].run(scene_dir, protocol)


def _without_times(outcomes):
    return [(o.scene, o.method, o.protocol, o.status,
             None if o.result is None else replace(o.result, wall_time_s=0.0))
            for o in outcomes]


@pytest.mark.slow  # processes start in seconds: kept out of the fast subset
def test_heavy_runs_in_processes_give_the_local_results(tiny_benchmark, tmp_path):
    scenes = find_scene_folders(tiny_benchmark)
    light = method_specs(("2D-SS",), ("ideal",), tmp_path)[0]
    heavy = _heavy_2ds(tmp_path)
    local = run_missing(scenes, [light, heavy], tmp_path / "local", log=_quiet)
    processes = run_missing(scenes, [light, heavy], tmp_path / "processes", log=_quiet,
                            execute=make_executor("processes", cpus=2))
    assert _without_times(processes) == _without_times(local)
    assert len(processes) == 3 * 2 and all(o.status == "ran" for o in processes)
    assert sorted(p.name for p in (tmp_path / "processes").iterdir()) == sorted(
        p.name for p in (tmp_path / "local").iterdir())


@pytest.mark.slow  # processes start in seconds: kept out of the fast subset
def test_auto_runs_heavy_runs_at_once_only_when_two_fit(tiny_benchmark, tmp_path):
    scenes = find_scene_folders(tiny_benchmark)
    for cores, expect_here in ((1.0, False), (2.0, True)):
        pids = tmp_path / f"pids-{cores}"
        pids.mkdir()
        spec = _heavy_2ds(tmp_path, cores, run=partial(_2ds_noting_its_process, str(pids)))
        outcomes = run_missing(scenes, [spec], tmp_path / f"results-{cores}", log=_quiet,
                               execute=make_executor("auto", cpus=2))
        assert [o.status for o in outcomes] == ["ran"] * 3
        ran_here = {int(p.read_text()) == os.getpid() for p in pids.iterdir()}
        assert ran_here == {expect_here}, f"{cores} cores a run"


@pytest.mark.slow  # processes start in seconds: kept out of the fast subset
def test_a_run_whose_process_dies_fails_alone(tiny_benchmark, tmp_path):
    scenes = find_scene_folders(tiny_benchmark)
    spec = _heavy_2ds(tmp_path, run=_dies_on_first_scene)
    messages = []
    outcomes = run_missing(scenes, [spec], tmp_path / "results", log=messages.append,
                           execute=make_executor("processes", cpus=2))
    status = {o.scene: (o.status, o.reason) for o in outcomes}
    assert status["tiny_l_shaped"][0] == "failed"
    assert "its process failed" in status["tiny_l_shaped"][1]
    assert "exited with code 3" in status["tiny_l_shaped"][1]
    assert [s for s, (st, _) in status.items() if st == "ran"] == [
        s.name for s in scenes if s.name != "tiny_l_shaped"]
    assert len(messages) == 1
    assert not (tmp_path / "results" / "tiny_l_shaped__2D-S__ideal.json").exists()


@pytest.mark.slow
def test_a_heavy_run_s_progress_is_shown_by_the_parent(tiny_benchmark, tmp_path, capsys):
    scenes = find_scene_folders(tiny_benchmark)[:2]
    spec = _heavy_2ds(tmp_path, run=_2ds_after_a_counted_loop)
    outcomes = run_missing(scenes, [spec], tmp_path / "results", log=_quiet,
                           execute=make_executor("processes", cpus=2))
    assert [o.status for o in outcomes] == ["ran"] * 2
    err = capsys.readouterr().err  # not a terminal: a plain line when a run first reports
    for scene in scenes:
        assert re.search(rf"(^|\r)fake training {scene.name}: 1/3 steps, [0-9.]+ steps/s, "
                         r"[0-9:]+ left$", err, re.MULTILINE), err


def test_neural3d_reserves_its_threads_or_a_share_of_the_gpu_and_records_neither_share():
    assert reserve(Neural3dBudget(threads=1)) == (1.0, 0.0)
    assert reserve(Neural3dBudget(threads=3)) == (3.0, 0.0)
    assert reserve(Neural3dBudget(device="cuda")) == (1.0, 1.0 / 8)
    assert reserve(Neural3dBudget(device="cuda:0", runs_per_gpu=4)) == (1.0, 0.25)
    assert METHOD_NEURAL3D.cpus_gpus(Neural3dBudget(threads=1)) == (1.0, 0.0)
    # The share changes no result, so results made with another share are reused.
    assert record_config(Neural3dBudget(runs_per_gpu=2)) == record_config(Neural3dBudget())
    assert "runs_per_gpu" in asdict(Neural3dBudget())
    with pytest.raises(ValueError, match="runs per GPU must be >= 1"):
        Neural3dBudget(runs_per_gpu=0)


NEURAL3D_TINY = ["--methods", "neural3d", "--neural3d-preset", "tiny", "--neural3d-steps",
                 "20", "--neural3d-resolution", "24", "--neural3d-threads", "1"]


@pytest.mark.slow
def test_neural3d_trained_two_at_a_time_gives_the_local_results(tiny_benchmark, tmp_path):
    """The real heavy path: neural3d's spec travels to spawned processes, trains there
    (torch with one thread in each) and its run folders land where the local run's do."""
    results = {}
    for executor in ("local", "processes"):
        out = tmp_path / executor
        command = [sys.executable, "-m", "metrics.compare", "--data", str(tiny_benchmark),
                   *NEURAL3D_TINY, "--results", str(out / "results"), "--out",
                   str(out / "compare"), "--executor", executor, "--cpus", "2"]
        done = subprocess.run(command, capture_output=True, text=True, timeout=600)
        assert done.returncode == 0, done.stderr[-3000:]
        if executor == "processes":  # each training's progress reached the parent's log
            for scene in find_scene_folders(tiny_benchmark):
                assert re.search(rf"neural3d {scene.name}: \d+/20 steps", done.stderr)
        results[executor] = {p.name: replace(read_result(p), wall_time_s=0.0)
                             for p in sorted((out / "results").glob("*.json"))}
        runs = sorted(p.name for p in (out / "results" / "neural3d_runs").iterdir())
        assert runs == sorted(s.name for s in find_scene_folders(tiny_benchmark))
    assert len(results["local"]) == 3
    assert results["processes"] == results["local"]  # every field, the provenance included


@pytest.mark.slow
def test_ctrl_c_stops_the_trainings_with_checkpoints_and_whole_results(
        tiny_benchmark, tmp_path):
    """SIGINT after the 2D results, while two neural3d trainings (100000 steps) run in their
    processes: the CLI exits 130 at once, each training saved its checkpoint (SIGTERM), and
    every result file is whole."""
    results = tmp_path / "results"
    command = [sys.executable, "-m", "metrics.compare", "--data", str(tiny_benchmark),
               "--methods", "2D-S,neural3d", "--views", "ideal,train", "--neural3d-preset", "tiny",
               "--neural3d-steps", "100000", "--neural3d-threads", "1", "--results",
               str(results), "--out", str(tmp_path / "out"), "--executor", "processes",
               "--cpus", "2"]
    proc = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    runs = results / "neural3d_runs"
    lines: list[str] = []
    reader = threading.Thread(target=lambda: lines.extend(iter(proc.stderr.readline, "")),
                              daemon=True)
    reader.start()
    try:
        # Both training loops run once both have reported progress (a fixed wait after their
        # config.json was not enough on a busy machine: a training still loading its scene
        # has no checkpoint to save).
        deadline = time.monotonic() + 300
        while len(set(re.findall(r"neural3d (\S+): \d+/100000 steps", "".join(lines)))) < 2:
            if proc.poll() is not None or time.monotonic() > deadline:
                proc.kill()
                reader.join(timeout=10)
                pytest.fail(f"two trainings did not start: {''.join(lines)[-3000:]}")
            time.sleep(0.1)
        tic = time.monotonic()
        proc.send_signal(signal.SIGINT)
        proc.wait(timeout=120)
        reader.join(timeout=10)
        stderr = "".join(lines)
    finally:  # never leave a 100000-step training behind
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 130, stderr
    assert time.monotonic() - tic < 60 and "interrupted" in stderr
    written = sorted(p for p in results.iterdir() if p.is_file())
    assert [p.name for p in written] == [f"{s.name}__2D-S__{protocol}.json"  # light runs first
                                         for s in find_scene_folders(tiny_benchmark)
                                         for protocol in ("ideal", "train")]
    for path in written:
        read_result(path)
    started = [p for p in runs.iterdir() if (p / "config.json").exists()]
    assert len(started) == 2 and all((p / "checkpoint.pt").is_file() for p in started)
