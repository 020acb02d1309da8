"""The progress of the tasks running in processes of their own, shown in the process that
started them (:func:`envelope.executors.process_tasks.run_in_processes`).

On a terminal, one tqdm line per running task, below the caller's own bars: steps done / total,
steps per second, time left, and what the task's bar shows after them (a training's loss).
Elsewhere (a CI log, a file) a bar redrawn in place would be noise, so each task gets a plain
line when it first reports and then at most every ``every_s`` seconds.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable

from tqdm import tqdm

from envelope.progress import Progress

LOG_EVERY_S = 30.0


class TaskProgressLines:
    """Call with ``(task, progress)`` as reports come, and ``(task, None)`` when the task is
    over; ``interactive`` (default: whether stderr is a terminal) chooses bars or lines;
    ``clock`` (seconds) decides when a line is due."""

    def __init__(self, *, interactive: bool | None = None, every_s: float = LOG_EVERY_S,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.interactive = sys.stderr.isatty() if interactive is None else interactive
        self.every_s = every_s
        self.clock = clock
        self.bars: dict[int, tqdm] = {}
        self.logged_at: dict[int, float] = {}

    def __call__(self, task: int, progress: Progress | None) -> None:
        if progress is None:
            bar = self.bars.pop(task, None)
            if bar is not None:
                bar.close()
            self.logged_at.pop(task, None)
        elif self.interactive:
            self._draw(task, progress)
        else:
            now = self.clock()
            if task not in self.logged_at or now - self.logged_at[task] >= self.every_s:
                self.logged_at[task] = now
                tqdm.write(progress_line(progress), file=sys.stderr)

    def close(self) -> None:
        """Remove every bar still shown (the tasks were stopped)."""
        for task in list(self.bars):
            self(task, None)

    def _draw(self, task: int, progress: Progress) -> None:
        bar = self.bars.get(task)
        if bar is None:
            bar = self.bars[task] = tqdm(total=progress.total, initial=progress.initial,
                                         desc=progress.label, unit="step", leave=False,
                                         dynamic_ncols=True)
        bar.set_postfix_str(progress.postfix, refresh=False)
        bar.update(progress.done - bar.n)


def progress_line(progress: Progress) -> str:
    """One line, e.g. ``neural3d tiny_skyscraper: 300/2000 steps, 10.5 steps/s, 2:42 left;
    loss=0.0123``."""
    of = "" if progress.total is None else f"/{progress.total}"
    rate, left = progress.rate_per_s, progress.left_s
    parts = [f"{progress.label}: {progress.done}{of} steps"]
    if rate is not None:
        parts.append(f"{rate:.1f} steps/s")
    if left is not None:
        parts.append(f"{tqdm.format_interval(left)} left")
    return ", ".join(parts) + (f"; {progress.postfix}" if progress.postfix else "")
