"""Run only the missing (scene, method, protocol) results; reuse the ones already on disk.

A stored result is reused when it reads back and its config matches the one
requested (every key of the requested config has the same value in the
stored one, compared as JSON). Otherwise the method runs and its result is
written with :func:`dataset.results.write_result`. A method that raises is
recorded as a failed outcome with its reason; the other runs go on.

The runs that are missing go to an executor (:data:`Execute`): here, one
after the other in this process (:func:`execute_local`); on a Ray cluster
with :mod:`metrics.executors`. Either way only this process writes the
result files, as each run comes back.
"""

from __future__ import annotations

import json
import time
import traceback
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Literal

from tqdm import tqdm

from dataset.ray_tasks import TaskResources
from dataset.results import MethodResult, read_result, result_filename, write_result

RunFn = Callable[[Path, str], MethodResult]
"""(scene folder, protocol) -> the method's result for that scene; may raise."""
OutcomeStatus = Literal["reused", "ran", "failed"]


@dataclass(frozen=True)
class MethodSpec:
    """A method as the comparison runs it.

    ``config`` is the config the method will run with, as it appears in its
    result JSON; ``has_footprint`` says whether it estimates a footprint;
    ``resources`` what one run reserves on a cluster node. ``artefacts_dir``:
    where ``run`` writes a folder per scene (named by the scene) that the
    comparison keeps (neural3d's run folder); such a ``run`` also takes an
    ``artefacts_dir=`` keyword to write it elsewhere (a worker on another machine).
    """

    name: str
    protocols: tuple[str, ...]
    config: dict[str, Any]
    run: RunFn
    has_footprint: bool = False
    resources: TaskResources = TaskResources()
    artefacts_dir: Path | None = None


@dataclass(frozen=True)
class Outcome:
    """What happened to one (scene, method, protocol); ``result`` is ``None`` if it failed."""

    scene: str
    method: str
    protocol: str
    status: OutcomeStatus
    result: MethodResult | None = None
    reason: str = ""
    path: Path | None = None


@dataclass(frozen=True)
class Job:
    """One run to make: ``spec`` on ``scene_dir`` under ``protocol``; the method writes its
    artefacts folder under ``artefacts_dir`` (``None``: under ``spec.artefacts_dir``)."""

    scene_dir: Path
    spec: MethodSpec
    protocol: str
    artefacts_dir: Path | None = None


RunOne = Callable[[Job], Outcome]
Execute = Callable[[Sequence[Job], RunOne], Iterator[tuple[int, Outcome]]]
"""(jobs, run_one) -> ``(index into jobs, run_one's outcome)`` for every job, in any order."""


def execute_local(jobs: Sequence[Job], run_one: RunOne) -> Iterator[tuple[int, Outcome]]:
    """Run the jobs one after the other in this process."""
    for i, job in enumerate(jobs):
        yield i, run_one(job)


def find_scenes(data: str | Path) -> list[Path]:
    """Scene folders in ``data``: ``data`` itself if it is one, else its sub-folders that are.

    A scene folder holds ``transforms.json`` (images to run methods on) or
    ``building.json`` (ground truth). Raises ``ValueError`` when there is none.
    """
    data = Path(data)
    if not data.is_dir():
        raise ValueError(f"data folder {data} does not exist")
    if _is_scene(data):
        return [data]
    scenes = sorted(p for p in data.iterdir() if p.is_dir() and _is_scene(p))
    if not scenes:
        raise ValueError(
            f"{data} holds no scene folder (one with transforms.json or building.json); "
            "make a benchmark with `python -m dataset.generate --preset tiny --out DIR`"
        )
    return scenes


def config_matches(requested: dict[str, Any], stored: dict[str, Any]) -> bool:
    """Whether every key of ``requested`` has the same value in ``stored`` (nested, as JSON)."""
    return _subset(_as_json(requested), _as_json(stored))


def run_missing(
    scene_dirs: Sequence[Path],
    specs: Sequence[MethodSpec],
    results_dir: str | Path,
    *,
    allow_run: bool = True,
    log: Callable[[str], None] = tqdm.write,
    execute: Execute = execute_local,
) -> list[Outcome]:
    """One :class:`Outcome` per (scene, method, protocol), in that nesting order.

    The runs that are missing go to ``execute``; each result is written as it
    comes back, so an interrupted call keeps what finished. With
    ``allow_run=False`` nothing runs: any stored result is used whatever its
    config, and a missing one is a failed outcome.
    """
    results_dir = Path(results_dir)
    jobs = [Job(s, spec, p) for s in scene_dirs for spec in specs for p in spec.protocols]
    outcomes: list[Outcome | None] = [_stored(job, results_dir, allow_run, log) for job in jobs]
    todo = [i for i, o in enumerate(outcomes) if o is None]
    with tqdm(total=len(jobs), initial=len(jobs) - len(todo), desc="results", unit="run",
              leave=False) as bar:
        for k, outcome in execute([jobs[i] for i in todo], run_job):
            if outcomes[todo[k]] is not None:
                raise RuntimeError(f"the executor returned run {k} twice")
            if outcome.result is not None:
                outcome = replace(outcome, path=write_result(results_dir, outcome.result))
            else:
                log(f"{outcome.scene} / {outcome.method} / {outcome.protocol}: failed: "
                    f"{outcome.reason}")
            outcomes[todo[k]] = outcome
            bar.update()
    done = [o for o in outcomes if o is not None]
    if len(done) != len(jobs):
        raise RuntimeError(f"the executor returned no outcome for {len(jobs) - len(done)} run(s)")
    return done


def run_job(job: Job) -> Outcome:
    """Run one job and return its outcome (``ran`` or ``failed``); writes no result file.

    Pure enough to run on another machine: it reads only ``job.scene_dir`` and
    writes only the method's artefacts folder.
    """
    scene, spec, protocol = job.scene_dir.name, job.spec, job.protocol
    where = {} if job.artefacts_dir is None else {"artefacts_dir": job.artefacts_dir}
    start = time.perf_counter()
    try:
        result = spec.run(job.scene_dir, protocol, **where)
    except Exception as exc:  # one failing method must not stop the comparison
        reason = f"{type(exc).__name__}: {exc}{_where(exc)}".strip()
        return Outcome(scene, spec.name, protocol, "failed", reason=reason)
    if result.scene != scene:
        result = replace(result, scene=scene)
    if not result.wall_time_s:
        result = replace(result, wall_time_s=time.perf_counter() - start)
    return Outcome(scene, spec.name, protocol, "ran", result)


def _stored(job: Job, results_dir: Path, allow_run: bool,
            log: Callable[[str], None]) -> Outcome | None:
    """The outcome of ``job`` without running it, or ``None`` if it has to run."""
    scene, spec, protocol = job.scene_dir.name, job.spec, job.protocol
    path = results_dir / result_filename(scene, spec.name, protocol)
    stale = ""
    if path.is_file():
        try:
            stored = read_result(path)
        except ValueError as exc:
            stale = f"corrupt result file: {exc}"
        else:
            if not allow_run or config_matches(spec.config, stored.config):
                return Outcome(scene, spec.name, protocol, "reused", stored, path=path)
            stale = "stored result has another config"
    if not allow_run:
        reason = stale or f"no result file {path.name} (run without --no-run to compute it)"
        log(f"{scene} / {spec.name} / {protocol}: {reason}")
        return Outcome(scene, spec.name, protocol, "failed", reason=reason, path=path)
    if stale:
        log(f"{scene} / {spec.name} / {protocol}: {stale}; recomputing")
    return None


def _where(exc: BaseException) -> str:
    """`` (at pkg/module.py:LINE)`` of the innermost frame in this project's code, or ``""``."""
    root = Path(__file__).resolve().parent.parent
    frames = [f for f in traceback.extract_tb(exc.__traceback__)
              if Path(f.filename).resolve().is_relative_to(root)]
    if not frames or frames[-1].filename == __file__:
        return ""
    return f" (at {Path(frames[-1].filename).resolve().relative_to(root)}:{frames[-1].lineno})"


def _is_scene(folder: Path) -> bool:
    return (folder / "transforms.json").is_file() or (folder / "building.json").is_file()


def _as_json(obj: Any) -> Any:
    return json.loads(json.dumps(obj, default=str))


def _subset(requested: Any, stored: Any) -> bool:
    if isinstance(requested, dict):
        return isinstance(stored, dict) and all(
            k in stored and _subset(v, stored[k]) for k, v in requested.items()
        )
    return requested == stored
