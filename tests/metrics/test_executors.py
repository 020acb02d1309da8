"""The ray executor on a local Ray (2 CPUs, loopback): the same tables as the local one, a
killed worker is retried without losing or doubling a result, scenes reach workers without
a shared folder, and Ctrl-C leaves only whole result files.

Faults are injected by methods made here: they record each attempt as a line in a file
(the test machine shares its disk with the local Ray's workers, which a cluster need not).
"""

import contextlib
import io
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from dataclasses import replace
from pathlib import Path

import pytest

from envelope.executors.ray_tasks import LOCAL_ONLY_ENV, RayConfig
from envelope.method import artefacts_folder
from envelope.results import read_result
from envelope.scenes.scene import find_scene_folders
from metrics.compare import main
from metrics.run.executors import make_executor
from metrics.run.methods import method_specs
from metrics.run.runner import MethodSpec, run_missing

pytestmark = pytest.mark.slow  # every test here starts a local Ray cluster

# Before Ray is first imported (it reads its settings then): no usage reports, loopback only.
os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
os.environ.setdefault(LOCAL_ONLY_ENV, "0")
ray = pytest.importorskip("ray", reason="the ray executor needs Ray (scripts/setup.sh)")

CONFIG = RayConfig(max_retries=1)


@pytest.fixture(scope="module")
def local_ray():
    """One local Ray for the module (starting one takes seconds), on loopback only."""
    ray.init(address="local", num_cpus=2, include_dashboard=False, log_to_driver=False,
             object_store_memory=200 * 2**20)
    assert {n["NodeManagerAddress"] for n in ray.nodes()} == {"127.0.0.1"}
    yield
    ray.shutdown()


def _quiet(_message):
    pass


@contextlib.contextmanager
def _ctrl_c_raises():
    """SIGINT raises KeyboardInterrupt in this block, as in a terminal, even where the tests
    run with SIGINT ignored (a shell's background job: Python then installs no handler)."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _attempts(path: Path) -> list[str]:
    return path.read_text().splitlines() if path.is_file() else []


def _a_gpu(config):
    return 1.0, 1.0


def _faulty_2ds(log: Path, die_on: set[str], *, always: bool = False,
                raise_on: frozenset[str] = frozenset()) -> MethodSpec:
    """2D-S (ideal views) that logs each attempt and kills its worker on the first attempt
    (every attempt with ``always``) for scenes in ``die_on``; raises on ``raise_on``."""
    base = method_specs(("2D-S",), ("ideal",), log.parent)[0]

    def run(scene_dir, protocol):
        with log.open("a") as f:
            f.write(f"{scene_dir.name}\n")
        if scene_dir.name in raise_on:
            raise ValueError("no facade pixels in any view")
        first = log.read_text().splitlines().count(scene_dir.name) == 1
        if scene_dir.name in die_on and (always or first):
            os._exit(1)  # the worker process dies mid-task, as on a lost node
        return base.run(scene_dir, protocol)

    return replace(base, run=run)


def _csv_body(path: Path) -> str:
    """A table CSV without its first comment line (which holds the time it was made)."""
    lines = path.read_text().splitlines(keepends=True)
    assert lines[0].startswith("# produced by")
    return "".join(lines[1:])


@pytest.mark.slow
def test_2d_methods_give_the_same_tables_with_ray_and_local(local_ray, tiny_benchmark, tmp_path):
    tables = {}
    for name in ("local", "ray"):
        results, out = tmp_path / f"results-{name}", tmp_path / f"out-{name}"
        with contextlib.redirect_stdout(io.StringIO()):
            code = main(["--data", str(tiny_benchmark), "--methods", "2D-S,2D-SS",
                         "--results", str(results), "--out", str(out), "--executor", name])
        assert code == 0
        tables[name] = {f: _csv_body(out / f)
                        for f in ("table2_errors.csv", "table3_footprint_iou.csv")}
        tables[name]["results"] = [replace(read_result(p), wall_time_s=0.0)
                                   for p in sorted(results.glob("*.json"))]
    assert len(tables["local"]["results"]) == 3 * 2 * 3  # scenes x methods x ideal,multi,train
    assert tables["ray"] == tables["local"]  # CSV bodies byte for byte, every result field


def test_a_task_the_cluster_cannot_place_is_refused_and_names_are_checked(
        local_ray, tiny_benchmark, tmp_path):
    spec = method_specs(("2D-S",), ("ideal",), tmp_path)[0]
    spec = replace(spec, method=replace(spec.method, reserve=_a_gpu))
    with pytest.raises(ValueError, match="needs 1 GPU"):
        run_missing(find_scene_folders(tiny_benchmark), [spec], tmp_path / "results", log=_quiet,
                    execute=make_executor("ray", CONFIG))
    assert not (tmp_path / "results").exists()
    with pytest.raises(ValueError, match="unknown executor"):
        make_executor("slurm")


@pytest.mark.slow
def test_a_killed_worker_is_retried_and_no_result_is_lost_or_doubled(
        local_ray, tiny_benchmark, tmp_path):
    scenes = find_scene_folders(tiny_benchmark)
    log = tmp_path / "attempts.txt"
    victim = scenes[0].name
    spec = _faulty_2ds(log, {victim})
    outcomes = run_missing(scenes, [spec], tmp_path / "results", log=_quiet,
                           execute=make_executor("ray", CONFIG))
    assert [(o.scene, o.status) for o in outcomes] == [(s.name, "ran") for s in scenes]
    assert sorted(_attempts(log)) == sorted([s.name for s in scenes] + [victim])
    files = sorted(p.name for p in (tmp_path / "results").iterdir())
    assert files == sorted(f"{s.name}__2D-S__ideal.json" for s in scenes)
    local = run_missing(scenes, [replace(spec, run=method_specs(
        ("2D-S",), ("ideal",), tmp_path)[0].run)], tmp_path / "local", log=_quiet)
    assert [replace(o.result, wall_time_s=0.0) for o in outcomes] == [
        replace(o.result, wall_time_s=0.0) for o in local]


@pytest.mark.slow
def test_retries_are_bounded_and_an_input_failure_is_not_retried(
        local_ray, tiny_benchmark, tmp_path):
    scenes = find_scene_folders(tiny_benchmark)
    log = tmp_path / "attempts.txt"
    dies, fails = scenes[0].name, scenes[1].name
    spec = _faulty_2ds(log, {dies}, always=True, raise_on=frozenset({fails}))
    messages = []
    outcomes = run_missing(scenes, [spec], tmp_path / "results", log=messages.append,
                           execute=make_executor("ray", CONFIG))
    status = {o.scene: (o.status, o.reason) for o in outcomes}
    assert status[dies][0] == "failed" and "Ray task lost" in status[dies][1]
    assert status[fails][0] == "failed" and "no facade pixels" in status[fails][1]
    assert status[scenes[2].name][0] == "ran"
    attempts = _attempts(log)
    assert attempts.count(dies) == CONFIG.max_retries + 1 and attempts.count(fails) == 1
    assert len(messages) == 2 and not (tmp_path / "results" / f"{dies}__2D-S__ideal.json").exists()


@pytest.mark.slow
def test_a_scene_reaches_the_worker_without_a_shared_folder(local_ray, tiny_benchmark, tmp_path):
    """The method removes the driver's scene folder before reading its own copy, and writes
    an artefacts folder that comes back to the driver (as neural3d's run folder does), to the
    place :func:`artefacts_folder` names for the job's protocol (here not the orbit's)."""
    driver_scene = tmp_path / "data" / "tiny_skyscraper"
    shutil.copytree(tiny_benchmark / "tiny_skyscraper", driver_scene)
    base = method_specs(("2D-S",), ("ideal",), tmp_path)[0]
    expected = base.run(driver_scene, "ideal")

    def run(scene_dir, protocol, artefacts_dir=tmp_path / "runs"):
        assert scene_dir != driver_scene and artefacts_dir != tmp_path / "runs"
        shutil.rmtree(driver_scene)  # from here on only the worker's copy exists
        extract = artefacts_folder(artefacts_dir, scene_dir.name, protocol) / "extract"
        extract.mkdir(parents=True)
        (extract / "mesh.ply").write_bytes(b"ply\n" + scene_dir.name.encode())
        return base.run(scene_dir, protocol)

    spec = replace(base, run=run, artefacts_dir=tmp_path / "runs")
    [outcome] = run_missing([driver_scene], [spec], tmp_path / "results", log=_quiet,
                            execute=make_executor("ray", CONFIG))
    assert not driver_scene.exists()
    assert outcome.status == "ran", outcome.reason
    assert replace(outcome.result, wall_time_s=0.0, provenance=None) == replace(
        expected, wall_time_s=0.0)
    mesh = tmp_path / "runs" / "ideal" / "tiny_skyscraper" / "extract" / "mesh.ply"
    assert mesh.read_bytes() == b"ply\ntiny_skyscraper"


@pytest.mark.slow
def test_sigint_to_the_driver_cancels_tasks_and_leaves_only_whole_results(
        local_ray, tiny_benchmark, tmp_path):
    scenes = find_scene_folders(tiny_benchmark)
    results = tmp_path / "results"
    quick = method_specs(("2D-S",), ("ideal",), tmp_path)[0]
    started, finished = tmp_path / "slow-started", tmp_path / "slow-finished"
    slow_scene = scenes[0].name

    def slow_run(scene_dir, protocol):
        if scene_dir.name == slow_scene:
            started.touch()
            time.sleep(120)
            finished.touch()
        return replace(quick.run(scene_dir, protocol), method="slow")

    slow = replace(quick, method=replace(quick.method, name="slow"), run=slow_run)
    others = [results / f"{s.name}__{m}__ideal.json" for s in scenes for m in ("2D-S", "slow")
              if (s.name, m) != (slow_scene, "slow")]

    sent = {}

    def interrupt_when_only_the_slow_task_is_left():
        deadline = time.monotonic() + 110
        while time.monotonic() < deadline:
            if started.exists() and all(p.exists() for p in others):
                sent["at"] = time.monotonic()
                os.kill(os.getpid(), signal.SIGINT)  # what Ctrl-C in a terminal sends
                return
            time.sleep(0.05)

    threading.Thread(target=interrupt_when_only_the_slow_task_is_left, daemon=True).start()
    with _ctrl_c_raises(), pytest.raises(KeyboardInterrupt):
        run_missing(scenes, [quick, slow], results, log=_quiet,
                    execute=make_executor("ray", CONFIG))
    # The interrupt ended the run at once: the slow task (120 s) did not run to its end.
    assert time.monotonic() - sent["at"] < 30
    assert sorted(results.iterdir()) == sorted(others)  # no temporary or partial file
    for path in others:
        read_result(path)
    time.sleep(1.0)
    assert not finished.exists()  # cancelled on the worker, not left running

    fast = replace(slow, run=lambda scene_dir, protocol: replace(
        quick.run(scene_dir, protocol), method="slow"))
    again = run_missing(scenes, [quick, fast], results, log=_quiet,
                        execute=make_executor("ray", CONFIG))
    assert [(o.scene, o.method, o.status) for o in again if o.status == "ran"] == [
        (slow_scene, "slow", "ran")]
    assert len(again) == 2 * len(scenes)


@pytest.mark.slow
def test_ctrl_c_stops_the_cli_with_whole_results_only(tiny_benchmark, tmp_path):
    """``python -m metrics.compare --executor ray`` (its own Ray) gets SIGINT after its first
    result, while neural3d (100000 steps per building) still runs or waits."""
    results = tmp_path / "results"
    command = [sys.executable, "-m", "metrics.compare", "--data", str(tiny_benchmark),
               "--methods", "2D-S,neural3d", "--views", "ideal,train", "--neural3d-steps", "100000",
               "--results", str(results), "--out", str(tmp_path / "out"), "--executor", "ray",
               # three CPUs for its Ray: a training (2) and a 2D-S task (1) fit at once, so a
               # 2D-S result comes even when Ray starts the trainings first
               "--cpus", "3"]
    # SIGINT as in a terminal, even where this test runs with it ignored (a background job)
    proc = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        deadline = time.monotonic() + 300  # Ray's start and 2D-S on a busy 2-core machine
        while not list(results.glob("*.json")) and proc.poll() is None:
            if time.monotonic() > deadline:
                proc.kill()
                pytest.fail(f"no result appeared in 300 s: {proc.communicate()[1][-3000:]}")
            time.sleep(0.1)
        time.sleep(1.0)
        proc.send_signal(signal.SIGINT)
        _, stderr = proc.communicate(timeout=60)
    finally:  # never leave a 100000-step training behind
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 130, stderr
    assert "interrupted" in stderr
    written = sorted(p for p in results.iterdir() if p.is_file())
    assert written and all(p.name.endswith(("__2D-S__ideal.json", "__2D-S__train.json"))
                           for p in written)
    for path in written:  # whole files only: each reads back
        read_result(path)
    runs = results / "neural3d_runs"
    assert not runs.exists() or not any(runs.iterdir())  # no half-returned run folder
    assert not (tmp_path / "out").exists()  # no table was written
