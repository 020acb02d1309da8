"""Run independent tasks on a Ray cluster (or a Ray started on this machine) and collect them.

The one place that talks to Ray. Callers hand over a function and its
argument tuples with the resources each task needs; results come back as the
tasks finish. Nothing here assumes a shared file system: arguments and return
values travel through Ray's object store (:mod:`envelope.executors.folder_pack` turns
folders into bytes for that). Ray is imported only when a session starts, so
the rest of the project runs without it.

Faults: a task whose worker process or node dies is re-run by Ray up to
``RayConfig.max_retries`` times; an exception raised by the task itself is
not retried (it would fail again on the same input) and, like a task that
ran out of retries, comes back as :class:`TaskLost`. Leaving the iteration
early (Ctrl-C, an error in the caller) cancels every task not yet collected.
"""

from __future__ import annotations

import argparse
import logging
import os
import socket
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any, Literal, get_args

WAIT_S = 0.5  # longest a wait for results blocks, so that Ctrl-C is seen promptly
LOCAL_ONLY_ENV = "RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"  # read once, when ray is first imported
LOCAL_OBJECT_STORE_MB = 512  # a Ray started here: the scenes in flight, not 30 % of the RAM


@dataclass(frozen=True)
class TaskResources:
    """What one task reserves on a Ray node: CPU cores and GPUs (fractions allowed)."""

    cpus: float = 1.0
    gpus: float = 0.0

    def __post_init__(self) -> None:
        if self.cpus < 0 or self.gpus < 0:
            raise ValueError(f"task resources must be >= 0, got {self}")


@dataclass(frozen=True)
class RayConfig:
    """Where tasks run and how often one is re-run after its worker died.

    ``address``: ``None`` starts a Ray on this machine for the run (loopback
    only, no dashboard); ``"auto"`` or ``"HOST:PORT"`` joins a running cluster
    (``ray start --head``). ``num_cpus``: cores a Ray started here may use
    (default: all). ``max_retries``: re-runs of a task whose worker died.
    """

    address: str | None = None
    num_cpus: int | None = None
    max_retries: int = 2

    def __post_init__(self) -> None:
        if self.num_cpus is not None and self.num_cpus < 1:
            raise ValueError(f"Ray num_cpus must be >= 1, got {self.num_cpus}")
        if self.max_retries < 0:
            raise ValueError(f"Ray max_retries must be >= 0, got {self.max_retries}")


@dataclass(frozen=True)
class TaskLost:
    """A task that gave no value: it raised, or its worker died more often than retried."""

    reason: str


@contextmanager
def ray_session(config: RayConfig) -> Iterator[None]:
    """Connect to (or start) Ray for the block and disconnect after it.

    A Ray already initialised in this process (a test's, a notebook's) is used
    as it is and left running.

    Raises
    ------
    ValueError
        If Ray is not installed or the cluster at ``config.address`` cannot be reached.
    """
    # No usage reports and no dashboard: a Ray started here needs nothing beyond loopback.
    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
    if config.address is None:
        # Ray's switch for a one-machine Ray (as on macOS): node address 127.0.0.1 and every
        # server bound to loopback, instead of the address of the network interface.
        os.environ.setdefault(LOCAL_ONLY_ENV, "0")
    try:
        import ray
    except ImportError as exc:
        raise ValueError(
            "the ray executor needs Ray: pip install 'envelope-bench[cluster]' "
            "(or run scripts/setup.sh)"
        ) from exc
    if ray.is_initialized():
        yield
        return
    if config.address is not None:
        _check_reachable(config.address)
    options: dict[str, Any] = {
        "include_dashboard": False, "log_to_driver": False, "logging_level": logging.WARNING,
    }
    if config.address is None:
        options.update(num_cpus=config.num_cpus,
                       object_store_memory=LOCAL_OBJECT_STORE_MB * 2**20)
    try:
        # "local": a new Ray for this run, never one that happens to run here already.
        ray.init(address=config.address or "local", **options)
    except ConnectionError as exc:
        raise ValueError(
            f"cannot join the Ray cluster at {config.address!r}: {exc}; pass the address that "
            "`ray start --head` printed, and if the cluster uses token authentication (the "
            "default of `ray start --head`) set RAY_AUTH_MODE=token here with the head's "
            "~/.ray/auth_token"
        ) from exc
    try:
        yield
    finally:
        ray.shutdown()


def run_tasks(
    fn: Callable[..., Any],
    calls: Sequence[tuple[tuple[Any, ...], TaskResources]],
    *,
    max_retries: int,
) -> Iterator[tuple[int, Any]]:
    """Run ``fn(*args)`` for every ``(args, resources)`` in ``calls`` as Ray tasks.

    Yields ``(index into calls, value)`` in the order the tasks finish; the
    value is a :class:`TaskLost` for a task that raised or whose worker died
    ``max_retries + 1`` times. Arguments that are ``ray.ObjectRef`` reach
    ``fn`` as their values. Must run inside :func:`ray_session`.

    Raises
    ------
    ValueError
        If a task needs more CPUs or GPUs than the whole cluster has (it would
        wait for ever).
    """
    import ray

    _check_fits(calls, ray.cluster_resources())
    remote = ray.remote(fn)
    index = {
        remote.options(num_cpus=res.cpus, num_gpus=res.gpus, max_retries=max_retries,
                       retry_exceptions=False).remote(*args): i
        for i, (args, res) in enumerate(calls)
    }
    pending = list(index)
    try:
        while pending:
            done, pending = ray.wait(pending, num_returns=1, timeout=WAIT_S)
            for ref in done:
                try:
                    value = ray.get(ref)
                except ray.exceptions.RayError as exc:
                    value = TaskLost(_first_line(exc))
                yield index[ref], value
    finally:
        for ref in pending:  # Ctrl-C or an early exit: nothing keeps running for nobody
            ray.cancel(ref)


def _check_reachable(address: str, timeout_s: float = 5.0) -> None:
    """Fail fast on a ``HOST:PORT`` nobody answers at (Ray itself retries for minutes)."""
    host, _, port = address.removeprefix("ray://").rpartition(":")
    if not host or not port.isdigit():
        return  # "auto" and other forms Ray resolves itself
    try:
        socket.create_connection((host, int(port)), timeout=timeout_s).close()
    except OSError as exc:
        raise ValueError(
            f"cannot reach a Ray cluster at {address!r}: {exc.strerror or exc}; start one with "
            "`ray start --head` and pass the address it prints to --ray-address"
        ) from exc


def _check_fits(calls: Sequence[tuple[tuple[Any, ...], TaskResources]],
                cluster: dict[str, float]) -> None:
    for _, res in calls:
        for name, need in (("CPU", res.cpus), ("GPU", res.gpus)):
            if need > cluster.get(name, 0.0):
                raise ValueError(
                    f"a task needs {need:g} {name}(s) but the Ray cluster has "
                    f"{cluster.get(name, 0.0):g}; add a node that has them or run on cpu"
                )


def _first_line(exc: BaseException) -> str:
    cause = getattr(exc, "cause", None)  # RayTaskError: the task's own exception
    shown = cause if isinstance(cause, BaseException) else exc
    text = str(shown).strip().splitlines()
    return f"{type(shown).__name__}: {text[0] if text else ''}".strip()


ExecutorName = Literal["auto", "local", "processes", "ray"]
EXECUTORS: tuple[str, ...] = get_args(ExecutorName)


def add_executor_arguments(parser: argparse.ArgumentParser, local_help: str, task: str,
                           processes_help: str | None = None) -> None:
    """``--executor`` and ``--ray-address`` on a command line: ``local_help`` says what
    ``local`` does there, ``task`` what one Ray task is. With ``processes_help`` (what
    ``processes`` does there) also ``processes``, ``auto`` (the default then: ``processes``
    when two heavy runs fit at once, else ``local``) and ``--cpus``."""
    if processes_help:
        choices, default = EXECUTORS, "auto"
        what = (f"auto (the default: processes when two heavy runs fit at once, else local), "
                f"local ({local_help}), processes ({processes_help})")
    else:
        choices, default = ("local", "ray"), "local"
        what = f"local ({local_help}, the default)"
    parser.add_argument("--executor", choices=choices, default=default,
                        help=f"{what} or ray (one Ray task per {task}, on a Ray started here "
                        "or on --ray-address; docs/cluster.md)")
    parser.add_argument("--ray-address", metavar="ADDR",
                        help="with --executor ray: a running cluster (HOST:PORT as printed by "
                        "`ray start --head`, or auto); default: start Ray on this machine")
    if processes_help:
        parser.add_argument("--cpus", type=_positive_int, metavar="N",
                            help="cores the runs may fill at once: with --executor processes "
                            "or auto, and a Ray started here (default: all of this machine's)")


def _positive_int(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1, got {value}")
    return value
