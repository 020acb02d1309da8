"""Where the photos source's time goes: wall seconds per stage, recorded in the scene's
``photos`` record (``seconds``) and printed, so a user sees what a large photo set costs.

A folder of photos runs every stage; a COLMAP project or a nerfstudio file runs reading,
the metric frame and writing (its poses are given).
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
STAGES = (READING, FEATURES, MATCHING, MAPPING, METRIC_FRAME, WRITING)
"""Every stage, in the order they run."""
TOTAL_KEY = "total"


@dataclass
class StageTimes:
    """Wall seconds spent in each stage so far (a stage entered twice adds up)."""

    seconds: dict[Stage, float] = field(default_factory=dict)

    @contextmanager
    def stage(self, stage: Stage) -> Iterator[None]:
        """Time the ``with`` block as ``stage``."""
        start = time.perf_counter()
        try:
            yield
        finally:
            self.seconds[stage] = self.seconds.get(stage, 0.0) + time.perf_counter() - start

    def record(self) -> dict[str, float]:
        """The ``seconds`` entry of the record: each stage that ran, by key, and their
        ``total``, rounded to 0.01 s."""
        ran = {s.key: round(self.seconds[s], 2) for s in STAGES if s in self.seconds}
        return {**ran, TOTAL_KEY: round(sum(self.seconds.values()), 2)}

    def summary(self) -> str:
        """One line for the terminal: each stage that ran and the total, in seconds."""
        ran = ", ".join(f"{s.key} {self.seconds[s]:.1f}" for s in STAGES if s in self.seconds)
        return f"seconds per stage: {ran}; {TOTAL_KEY} {sum(self.seconds.values()):.1f}"
