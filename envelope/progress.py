"""A long loop's progress bar: drawn here, or sent to the process that started this one.

A loop makes its bar with :func:`progress_bar` and calls ``update``, ``set_postfix`` and
``close`` on it as on a tqdm bar. In an ordinary process that is a tqdm bar. In a task
process of :mod:`envelope.executors.process_tasks` (a training that the comparison runs beside
others), whose own bars are off, the task's process has called :func:`send_progress_to`, and
the bar sends its :class:`Progress` there instead: at most every ``SEND_EVERY_S`` seconds, and
once more when it closes. The parent draws one line per running task. Sending costs a clock
read per ``update``; it changes nothing the loop computes.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from tqdm import tqdm

SEND_EVERY_S = 0.5


@dataclass(frozen=True)
class Progress:
    """Where a loop stands: ``done`` of ``total`` steps, its bar's ``label`` and ``postfix``
    (e.g. ``"loss=0.0123, psnr=24.50"``); ``elapsed_s`` since the bar was made, over which
    ``done - initial`` steps were taken."""

    label: str
    done: int
    total: int | None
    initial: int = 0
    elapsed_s: float = 0.0
    postfix: str = ""

    @property
    def rate_per_s(self) -> float | None:
        """Steps per second since the bar was made; ``None`` before any."""
        steps = self.done - self.initial
        return steps / self.elapsed_s if steps > 0 and self.elapsed_s > 0 else None

    @property
    def left_s(self) -> float | None:
        """Seconds left at that rate; ``None`` without a total or a rate."""
        rate = self.rate_per_s
        return None if self.total is None or rate is None else (self.total - self.done) / rate


Sink = Callable[[Progress], None]
_sink: Sink | None = None


def send_progress_to(sink: Sink | None) -> None:
    """From now on, bars made in this process send their progress to ``sink`` (``None``: they
    are tqdm bars again)."""
    global _sink
    _sink = sink


def progress_bar(*, total: int | None, desc: str, initial: int = 0,
                 **tqdm_options: Any) -> Any:
    """A tqdm bar, or where :func:`send_progress_to` set a sink, a :class:`SentBar`."""
    if _sink is None:
        return tqdm(total=total, initial=initial, desc=desc, **tqdm_options)
    return SentBar(_sink, total=total, desc=desc, initial=initial)


class SentBar:
    """The part of a tqdm bar a loop uses (``n``, ``update``, ``set_postfix``, ``close``),
    sending :class:`Progress` to a sink instead of drawing."""

    def __init__(self, sink: Sink, *, total: int | None, desc: str, initial: int = 0) -> None:
        self.sink, self.total, self.desc, self.initial = sink, total, desc, initial
        self.n = initial
        self.postfix = ""
        self.start = time.monotonic()
        self.sent_at = -float("inf")
        self.closed = False

    def update(self, n: int = 1) -> None:
        self.n += n
        if time.monotonic() - self.sent_at >= SEND_EVERY_S:
            self._send()

    def set_postfix(self, **values: Any) -> None:
        self.postfix = ", ".join(f"{k}={v}" for k, v in values.items())

    def close(self) -> None:
        if not self.closed:
            self.closed = True
            self._send()

    def __enter__(self) -> SentBar:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _send(self) -> None:
        self.sent_at = time.monotonic()
        self.sink(Progress(self.desc, self.n, self.total, self.initial,
                           self.sent_at - self.start, self.postfix))
