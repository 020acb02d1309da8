"""dataset.importers.photos.stage_times: seconds per stage, on a clock the test drives."""

from __future__ import annotations

import pytest

from dataset.importers.photos import stage_times
from dataset.importers.photos.stage_times import (
    FEATURES,
    MATCHING,
    READING,
    STAGES,
    StageTimes,
)


@pytest.fixture
def clock(monkeypatch):
    """``time.perf_counter`` reads ``now[0]`` and ``time.process_time`` half of it (one
core of two busy); the test moves it on."""
    now = [100.0]
    monkeypatch.setattr(stage_times.time, "perf_counter", lambda: now[0])
    monkeypatch.setattr(stage_times.time, "process_time", lambda: now[0] / 2)
    return now


def test_each_stage_gets_its_seconds_and_a_stage_entered_twice_adds_up(clock):
    times = StageTimes()
    with times.stage(MATCHING):
        clock[0] += 2.5
    with times.stage(READING):
        clock[0] += 1.004
    clock[0] += 50.0  # between stages: no stage's time
    with times.stage(MATCHING):
        clock[0] += 0.25
    # In the stages' order, not the order they ran; rounded to 0.01 s; the total their sum.
    assert times.record() == {
        "seconds": {"reading": 1.0, "matching": 2.75, "total": 3.75},
        "cpu_seconds": {"reading": 0.5, "matching": 1.38, "total": 1.88}}
    assert times.summary() == "seconds per stage: reading 1.0, matching 2.8; total 3.8"


def test_a_stage_that_raises_is_timed_all_the_same(clock):
    times = StageTimes()
    with pytest.raises(ValueError), times.stage(FEATURES):
        clock[0] += 3.0
        raise ValueError("no model")
    assert times.record()["seconds"] == {"features": 3.0, "total": 3.0}


def test_stages_have_distinct_keys_and_labels():
    assert len({s.key for s in STAGES}) == len({s.label for s in STAGES}) == len(STAGES) == 7
