"""Where the photos source's time goes: wall and CPU seconds per stage, recorded in the
scene's ``photos`` record (``seconds``, ``cpu_seconds``) and printed (wall), so a user sees
what a large photo set costs.

A folder of photos runs every stage; a COLMAP project runs reading, the metric frame,
writing and depth (its poses are given); a nerfstudio file the same but depth (it has no
points).
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field


@dataclass(frozen=True)
class Stage:
    """One stage: ``key`` in the record's ``seconds``, ``label`` where it is printed."""

    key: str
    label: str


READING = Stage("reading", "reading + upright copies s")
FEATURES = Stage("features", "feature extraction s")
MATCHING = Stage("matching", "matching s")
MAPPING = Stage("mapping", "mapping s")
METRIC_FRAME = Stage("metric_frame", "metric frame s")
WRITING = Stage("writing", "undistortion + writing s")
DEPTH = Stage("depth", "depth from the sparse points s")
STAGES = (READING, FEATURES, MATCHING, MAPPING, METRIC_FRAME, WRITING, DEPTH)
"""Every stage, in the order they run."""
TOTAL_KEY = "total"
SECONDS_KEY = "seconds"
"""The record's entry of wall seconds per stage."""
CPU_SECONDS_KEY = "cpu_seconds"
"""The record's entry of CPU seconds per stage (the process's, its threads included): on
cores shared with other work the wall seconds grow with the load, these do not."""


@dataclass
class StageTimes:
    """Wall and CPU seconds spent in each stage so far (a stage entered twice adds up)."""

    wall_s: dict[Stage, float] = field(default_factory=dict)
    cpu_s: dict[Stage, float] = field(default_factory=dict)

    @contextmanager
    def stage(self, stage: Stage) -> Iterator[None]:
        """Time the ``with`` block as ``stage``."""
        wall, cpu = time.perf_counter(), time.process_time()
        try:
            yield
        finally:
            self.wall_s[stage] = self.wall_s.get(stage, 0.0) + time.perf_counter() - wall
            self.cpu_s[stage] = self.cpu_s.get(stage, 0.0) + time.process_time() - cpu

    def record(self) -> dict[str, dict[str, float]]:
        """The record's :data:`SECONDS_KEY` and :data:`CPU_SECONDS_KEY` entries: each stage
        that ran, by key, and their ``total``, rounded to 0.01 s."""
        return {SECONDS_KEY: _by_key(self.wall_s), CPU_SECONDS_KEY: _by_key(self.cpu_s)}

    def summary(self) -> str:
        """One line for the terminal: each stage that ran and the total, in wall seconds."""
        ran = ", ".join(f"{s.key} {self.wall_s[s]:.1f}" for s in STAGES if s in self.wall_s)
        return f"seconds per stage: {ran}; {TOTAL_KEY} {sum(self.wall_s.values()):.1f}"


def _by_key(seconds: dict[Stage, float]) -> dict[str, float]:
    ran = {s.key: round(seconds[s], 2) for s in STAGES if s in seconds}
    return {**ran, TOTAL_KEY: round(sum(seconds.values()), 2)}
