"""Run independent tasks at once on this machine, each in a process of its own, as many at a
time as fit in the machine's cores and GPUs.

The one-machine counterpart of :mod:`envelope.executors.ray_tasks`: callers hand over a
function and its argument tuples with the :class:`~envelope.executors.ray_tasks.TaskResources`
each task reserves, and get the values back as the tasks finish. A task starts when what it
reserves fits in what the running ones leave of the :class:`Capacity`, earlier tasks first
(a later one that fits may pass an earlier one that does not); a task larger than the whole
capacity runs alone. Several tasks may share a GPU (each reserving a fraction of it).

Each task gets a fresh *spawned* process (not forked: Embree, BLAS and CUDA do not survive a
fork), so a task that crashes its process (a segfault, the OOM killer) costs only itself: it
comes back as :class:`~envelope.executors.ray_tasks.TaskLost`, as does a task that raises.
Tasks ignore Ctrl-C and draw no progress bars: a bar made with
:func:`envelope.progress.progress_bar` (a training's) sends its progress through the task's
pipe, ahead of the value, and this process shows it (``progress``: by default a
:class:`~envelope.executors.task_progress.TaskProgressLines`, a line per running task); leaving
the iteration early (Ctrl-C, an error in the caller) sends every running task SIGTERM, which
it turns into ``SystemExit`` so that its ``finally`` blocks (and
:func:`envelope.atomic.atomic_directory`) clean up what it was writing, and waits for it.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from functools import partial
from multiprocessing.connection import Connection, wait
from typing import Any

from envelope.executors.ray_tasks import TaskLost, TaskResources
from envelope.executors.task_progress import TaskProgressLines
from envelope.progress import Progress, send_progress_to

WAIT_S = 0.5  # longest a wait for a finished task blocks, so that Ctrl-C is seen promptly
_SLACK = 1e-9  # fractions of a GPU that add up to one
_PROGRESS, _VALUE = "progress", "value"  # what a task's message carries
_RUNNING = object()  # a task that has sent progress only, so far
ShowProgress = Callable[[int, Progress | None], None]
"""(task index, its progress; ``None`` once it is over)."""


@dataclass(frozen=True)
class Capacity:
    """What the running tasks may reserve together: CPU cores and GPUs."""

    cpus: float
    gpus: float = 0.0

    def __post_init__(self) -> None:
        if self.cpus < 1 or self.gpus < 0:
            raise ValueError(f"capacity needs >= 1 CPU and >= 0 GPUs, got {self}")


def machine_capacity(cpus: int | None = None, *, count_gpus: bool = False) -> Capacity:
    """This machine's capacity: ``cpus`` cores (default: the cores this process may run on)
    and, with ``count_gpus``, one GPU if torch sees a CUDA device (torch is imported only
    then). One, not all of them: the tasks name their device (``cuda`` is ``cuda:0``), so a
    machine with several GPUs takes one scheduler per device."""
    if cpus is None:
        cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (
            os.cpu_count() or 1)
    gpus = 0
    if count_gpus:
        import torch

        gpus = 1 if torch.cuda.is_available() else 0
    return Capacity(cpus=float(cpus), gpus=float(gpus))


def run_in_processes(
    fn: Callable[..., Any],
    calls: Sequence[tuple[tuple[Any, ...], TaskResources]],
    capacity: Capacity,
    progress: ShowProgress | None = None,
) -> Iterator[tuple[int, Any]]:
    """Run ``fn(*args)`` for every ``(args, resources)`` in ``calls``, each in its own spawned
    process, at most ``capacity`` reserved at once; what the tasks' progress bars report goes
    to ``progress`` (default: a :class:`TaskProgressLines`).

    Yields ``(index into calls, value)`` in the order the tasks finish; the value is a
    :class:`~envelope.executors.ray_tasks.TaskLost` for a task that raised, whose process died,
    or whose function or arguments cannot be sent to a process (they must pickle).
    """
    context = multiprocessing.get_context("spawn")
    show = TaskProgressLines() if progress is None else progress
    waiting = list(range(len(calls)))
    running: dict[int, tuple[Any, Connection]] = {}
    try:
        while waiting or running:
            for i in _startable(waiting, running, calls, capacity):
                waiting.remove(i)
                started = _start(context, fn, calls[i][0])
                if isinstance(started, TaskLost):
                    yield i, started
                else:
                    running[i] = started
            ready = set(wait([h for p, c in running.values() for h in (c, p.sentinel)],
                             timeout=WAIT_S))
            for i, (process, conn) in list(running.items()):
                if conn in ready or process.sentinel in ready:
                    value = _receive(process, conn, partial(show, i),
                                     exited=process.sentinel in ready)
                    if value is not _RUNNING:
                        del running[i]
                        show(i, None)
                        yield i, value
    finally:  # Ctrl-C or an early exit: nothing keeps running for nobody
        for i, (process, _) in running.items():
            process.terminate()
            show(i, None)
        for process, conn in running.values():
            process.join()
            conn.close()


def _startable(waiting: list[int], running: dict[int, Any],
               calls: Sequence[tuple[tuple[Any, ...], TaskResources]],
               capacity: Capacity) -> list[int]:
    """The waiting tasks to start now, earliest first: those that fit in what the running
    ones leave; if nothing runs and none fits, the earliest (it runs alone)."""
    cpus = capacity.cpus - sum(calls[i][1].cpus for i in running)
    gpus = capacity.gpus - sum(calls[i][1].gpus for i in running)
    chosen = []
    for i in waiting:
        need = calls[i][1]
        if need.cpus <= cpus + _SLACK and need.gpus <= gpus + _SLACK:
            chosen.append(i)
            cpus, gpus = cpus - need.cpus, gpus - need.gpus
    if not chosen and not running and waiting:
        chosen.append(waiting[0])
    return chosen


def _start(context: Any, fn: Callable[..., Any], args: tuple[Any, ...]
           ) -> tuple[Any, Connection] | TaskLost:
    """Start one task's process; a task that cannot be sent to it is lost at once."""
    receive, send = context.Pipe(duplex=False)
    process = context.Process(target=_task_main, args=(fn, args, send), daemon=True)
    try:
        with _environment(TQDM_DISABLE="1"):
            process.start()
    except Exception as exc:  # pickling the function or its arguments
        receive.close()
        return TaskLost(f"cannot start a process for it: {type(exc).__name__}: {exc}")
    finally:
        send.close()  # the child holds its own copy; EOF here once the child is gone
    return process, receive


def _receive(process: Any, conn: Connection, show: Callable[[Progress], None], *,
             exited: bool) -> Any:
    """Read what a task sent: its progress reports go to ``show``; then its value, a
    :class:`TaskLost` if its process ended without one, or ``_RUNNING`` if it goes on."""
    try:
        while conn.poll():
            kind, payload = conn.recv()
            if kind == _VALUE:
                _close(process, conn)
                return payload
            show(payload)
    except (EOFError, OSError):  # its end of the pipe closed without a value: it is gone
        exited = True
    if not exited:
        return _RUNNING
    _close(process, conn)
    return TaskLost(f"its process exited with code {process.exitcode} before it finished")


def _close(process: Any, conn: Connection) -> None:
    process.join()
    conn.close()


def _task_main(fn: Callable[..., Any], args: tuple[Any, ...], conn: Connection) -> None:
    """In the task's process: run it, sending its progress, then its value (or why it has
    none)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, _exit_on_sigterm)
    send_progress_to(lambda progress: conn.send((_PROGRESS, progress)))
    try:
        value = fn(*args)
    except (KeyboardInterrupt, SystemExit):
        return  # stopped by the caller (SIGTERM), which waits for no value any more
    except Exception as exc:
        value = TaskLost(f"{type(exc).__name__}: {exc}".strip())
    try:
        conn.send((_VALUE, value))
    except Exception as exc:  # a value that does not pickle
        conn.send((_VALUE, TaskLost(
            f"its value cannot be sent back: {type(exc).__name__}: {exc}")))
    conn.close()


def _exit_on_sigterm(signum: int, frame: Any) -> None:
    raise SystemExit(128 + signum)


@contextmanager
def _environment(**values: str) -> Iterator[None]:
    """Set environment variables for the block (a spawned child inherits them)."""
    before = {k: os.environ.get(k) for k in values}
    os.environ.update(values)
    try:
        yield
    finally:
        for key, value in before.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value
