"""A pool of worker processes that stops cleanly on Ctrl-C, ``kill`` or an error.

Workers are spawned (not forked: Embree and BLAS threads do not survive a
fork) and ignore Ctrl-C; the parent stops them with SIGTERM, which each turns
into ``SystemExit`` so that ``finally`` blocks and
:func:`envelope.atomic.atomic_directory` clean up what it was writing.
"""

from __future__ import annotations

import multiprocessing
import signal
from collections.abc import Iterator
from contextlib import contextmanager
from multiprocessing.pool import Pool
from typing import Any


@contextmanager
def worker_pool(workers: int) -> Iterator[Pool]:
    """Yield a pool of ``workers`` spawned processes; on leaving, wait for them to finish,
    or terminate them (and wait) if the block raised, Ctrl-C included."""
    if workers < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    pool = multiprocessing.get_context("spawn").Pool(workers, initializer=_init_worker)
    try:
        yield pool
        pool.close()
    except BaseException:
        pool.terminate()
        raise
    finally:
        pool.join()


def _init_worker() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, _exit_on_sigterm)


def _exit_on_sigterm(signum: int, frame: Any) -> None:
    raise SystemExit(128 + signum)
