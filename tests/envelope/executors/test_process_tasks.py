"""Tasks in processes of their own: values come back by index, no more run at once than the
capacity holds (GPU fractions included), a task that raises or dies is lost alone, and
leaving early stops the running tasks through their ``finally`` blocks.

Each task writes when it starts and ends into a folder; concurrency is read from those
marks, not from timings.
"""

import os
import time
from pathlib import Path

import pytest

from envelope.executors.process_tasks import Capacity, machine_capacity, run_in_processes
from envelope.executors.ray_tasks import TaskLost, TaskResources
from envelope.progress import Progress, progress_bar


def _marked(folder: str, i: int, sleep_s: float) -> int:
    """Mark the start, sleep, mark the end; the value is ``i * i``."""
    Path(folder, f"{i}.start").write_text(repr(time.monotonic()))
    time.sleep(sleep_s)
    Path(folder, f"{i}.end").write_text(repr(time.monotonic()))
    return i * i


def _most_at_once(folder: Path, n: int) -> int:
    spans = [(float((folder / f"{i}.start").read_text()), float((folder / f"{i}.end").read_text()))
             for i in range(n)]
    return max(sum(s <= t < e for s, e in spans) for t, _ in spans)


def _fails(kind: str) -> None:
    if kind == "raise":
        raise ValueError("no facade pixels in any view")
    os._exit(3)  # the process dies, as under the OOM killer


def _stopped(folder: str) -> None:
    Path(folder, "started").touch()
    try:
        time.sleep(120)
    finally:
        Path(folder, "cleaned-up").touch()


@pytest.mark.slow  # processes start in seconds: kept out of the fast subset
def test_values_come_back_by_index_and_the_cpus_bound_how_many_run_at_once(tmp_path):
    calls = [((str(tmp_path), i, 1.5), TaskResources(cpus=1.0)) for i in range(5)]
    got = dict(run_in_processes(_marked, calls, Capacity(cpus=2)))
    assert got == {i: i * i for i in range(5)}
    assert _most_at_once(tmp_path, 5) == 2


@pytest.mark.slow
def test_gpu_fractions_share_one_gpu_and_a_task_larger_than_the_machine_runs_alone(tmp_path):
    quarter = [((str(tmp_path), i, 2.0), TaskResources(cpus=1.0, gpus=0.25)) for i in range(4)]
    half = [((str(tmp_path), i, 1.5), TaskResources(cpus=1.0, gpus=0.5)) for i in range(4, 8)]
    big = [((str(tmp_path), 8, 0.3), TaskResources(cpus=4.0))]
    got = dict(run_in_processes(_marked, quarter, Capacity(cpus=8, gpus=1)))
    assert got == {i: i * i for i in range(4)} and _most_at_once(tmp_path, 4) == 4
    got = dict(run_in_processes(_marked, half + big, Capacity(cpus=2, gpus=1)))
    assert set(got) == set(range(5)) and got[4] == 8 * 8  # index into calls: the big one
    spans = {i: (float((tmp_path / f"{i}.start").read_text()),
                 float((tmp_path / f"{i}.end").read_text())) for i in range(4, 9)}
    big_start, big_end = spans[8]
    assert all(e <= big_start or s >= big_end for i, (s, e) in spans.items() if i != 8)
    assert max(sum(s <= t < e for s, e in spans.values()) for t, _ in spans.values()) == 2


def test_a_task_that_raises_or_dies_is_lost_alone():
    calls = [(("raise",), TaskResources()), (("die",), TaskResources()),
             ((7,), TaskResources())]
    got = dict(run_in_processes(_fails, calls[:2], Capacity(cpus=2)))
    assert isinstance(got[0], TaskLost) and got[0].reason == (
        "ValueError: no facade pixels in any view")
    assert isinstance(got[1], TaskLost) and "exited with code 3" in got[1].reason
    assert dict(run_in_processes(abs, [((-7,), TaskResources())], Capacity(cpus=1))) == {0: 7}


def test_a_function_that_cannot_reach_a_process_is_lost_at_once():
    got = dict(run_in_processes(lambda x: x, [((1,), TaskResources())], Capacity(cpus=1)))
    assert isinstance(got[0], TaskLost) and "cannot start a process" in got[0].reason


def _after(path: str) -> str:
    """Return once ``path`` exists (another task made it)."""
    while not Path(path).exists():
        time.sleep(0.05)
    return "seen"


def test_leaving_early_stops_running_tasks_through_their_finally_blocks(tmp_path):
    calls = [((str(tmp_path),), TaskResources()),
             ((str(tmp_path / "started"),), TaskResources())]
    functions = {0: _stopped, 1: _after}
    tasks = run_in_processes(_dispatch, [((functions[i], *args), r)
                                         for i, (args, r) in enumerate(calls)], Capacity(cpus=2))
    assert next(tasks) == (1, "seen")  # the slow task has started by now
    tic = time.monotonic()
    tasks.close()  # what Ctrl-C in the caller does
    assert time.monotonic() - tic < 30
    assert (tmp_path / "cleaned-up").exists()


def _dispatch(fn, *args):
    return fn(*args)


def _counts(steps: int, step_s: float) -> int:
    """A loop of ``steps`` steps with a progress bar, as a training has."""
    bar = progress_bar(total=steps, desc="count", initial=1)
    for _ in range(1, steps):
        time.sleep(step_s)
        bar.update()
    bar.set_postfix(loss="0.5000")
    bar.close()
    return steps


def test_a_task_s_progress_reaches_the_caller_before_its_value():
    seen = []

    def show(task, progress):
        seen.append((task, progress))

    got = dict(run_in_processes(_counts, [((4, 0.0), TaskResources())], Capacity(cpus=1),
                                progress=show))
    assert got == {0: 4}
    # The first update is sent at once, the next ones at most every 0.5 s, the last on close.
    assert seen[0] == (0, Progress("count", 2, 4, 1, seen[0][1].elapsed_s))
    assert seen[-2] == (0, Progress("count", 4, 4, 1, seen[-2][1].elapsed_s, "loss=0.5000"))
    assert seen[-1] == (0, None)  # over


def test_capacity_is_checked_and_the_machine_has_cores():
    with pytest.raises(ValueError, match=">= 1 CPU"):
        Capacity(cpus=0)
    assert machine_capacity().cpus >= 1 and machine_capacity(3).cpus == 3
    assert machine_capacity().gpus == 0
