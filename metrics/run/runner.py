"""Run only the missing (scene, method, protocol) results; reuse the ones already on disk.

Results are keyed by their provenance record (:mod:`envelope.provenance`): the
method's config, the fingerprint of the code it depends on, the scene's
fingerprint (its ``transforms.json``, which records how it was rendered) and
library versions. A stored result is reused only when its record equals the
one the current code would write (:func:`expected_provenance`); otherwise the
log says which part changed and the method runs again, unless ``reuse_stale``
keeps it on purpose (its outcome is then ``"stale"`` and the tables mark it).
Results are written with :func:`envelope.results.write_result`, carrying the
record. A method that raises is recorded as a failed outcome with its reason;
the other runs go on.

The runs that are missing go to an executor (:data:`Execute`): here, one
after the other in this process (:func:`execute_local`); on a Ray cluster
with :mod:`metrics.run.executors`. Either way only this process writes the
result files, as each run comes back.
"""

from __future__ import annotations

import time
import traceback
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Literal

from tqdm import tqdm

from envelope.executors.ray_tasks import TaskResources
from envelope.provenance import (
    Provenance,
    file_fingerprint,
    make_provenance,
    provenance_changes,
)
from envelope.results import MethodResult, read_result, result_filename, write_result
from envelope.scenes.scene import find_scene_folders as find_scenes  # noqa: F401

# ``find_scenes`` is :func:`envelope.scenes.scene.find_scene_folders`, the one scene finder,
# under the name metrics.compare and bench/ import it by.

RunFn = Callable[[Path, str], MethodResult]
"""(scene folder, protocol) -> the method's result for that scene; may raise."""
OutcomeStatus = Literal["reused", "stale", "ran", "failed"]
"""``stale``: a stored result whose provenance differs from the current one, kept on purpose."""


@dataclass(frozen=True)
class MethodSpec:
    """A method as the comparison runs it.

    ``config`` is the config the method will run with, as it appears in its
    result JSON; ``has_footprint`` says whether it estimates a footprint;
    ``resources`` what one run reserves on a cluster node. ``artefacts_dir``:
    where ``run`` writes a folder per scene (named by the scene) that the
    comparison keeps (a trained method's run folder); such a ``run`` also takes an
    ``artefacts_dir=`` keyword to write it elsewhere (a worker on another machine).
    ``mesh_file``: a semantic mesh inside a scene's artefacts folder, for the
    figures and the report; ``heavy``: run only at the highest severity of a
    robustness study (unless asked otherwise); ``debug_images(scene folder,
    protocol, folder)``: write its pipeline images. All of these come from the
    method's :class:`envelope.method.Method` (``metrics.run.methods``).
    ``code`` names the modules or packages whose source the results depend on and
    ``libraries`` the distributions whose versions they depend on: both go into
    each result's provenance record, so changing them recomputes the results.
    ``seed``: the training seed of a method whose config has one (neural3d); specs
    that differ only by it keep their results side by side (``__seed<k>`` files).
    ``paper_name``: the method's name in the BuildNet3D paper's tables, if it has one.
    """

    name: str
    protocols: tuple[str, ...]
    config: dict[str, Any]
    run: RunFn
    has_footprint: bool = False
    resources: TaskResources = TaskResources()
    artefacts_dir: Path | None = None
    code: tuple[str, ...] = ("envelope",)
    libraries: tuple[str, ...] = ("numpy",)
    mesh_file: str | None = None
    heavy: bool = False
    debug_images: Callable[[Path, str, Path], None] | None = None
    seed: int | None = None
    paper_name: str | None = None


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


def expected_provenance(scene_dir: Path, spec: MethodSpec) -> Provenance:
    """The provenance record the current code writes for ``spec`` run on ``scene_dir``.

    The scene's fingerprint is that of its ``transforms.json`` (generated scenes
    record their own provenance in it, so a re-render changes it).
    """
    transforms = scene_dir / "transforms.json"
    scene = file_fingerprint(transforms) if transforms.is_file() else "absent"
    return make_provenance(spec.config, modules=spec.code, inputs={"scene": scene},
                           libraries=spec.libraries)


def run_missing(
    scene_dirs: Sequence[Path],
    specs: Sequence[MethodSpec],
    results_dir: str | Path,
    *,
    allow_run: bool = True,
    reuse_stale: bool = False,
    log: Callable[[str], None] = tqdm.write,
    execute: Execute = execute_local,
) -> list[Outcome]:
    """One :class:`Outcome` per (scene, method, protocol), in that nesting order.

    The runs that are missing or stale go to ``execute``; each result is
    written as it comes back, with its provenance record, so an interrupted
    call keeps what finished. With ``reuse_stale`` a stored result made by
    other code or settings is kept (outcome ``"stale"``). With
    ``allow_run=False`` nothing runs: any stored result is used (stale ones
    marked so), and a missing one is a failed outcome.
    """
    results_dir = Path(results_dir)
    jobs = [Job(s, spec, p) for s in scene_dirs for spec in specs for p in spec.protocols]
    records = {(j.scene_dir, j.spec.name, j.spec.seed): expected_provenance(j.scene_dir, j.spec)
               for j in jobs}
    outcomes: list[Outcome | None] = [
        _stored(job, records[job.scene_dir, job.spec.name, job.spec.seed], results_dir,
                keep_stale=reuse_stale or not allow_run, allow_run=allow_run, log=log)
        for job in jobs]
    todo = [i for i, o in enumerate(outcomes) if o is None]
    with tqdm(total=len(jobs), initial=len(jobs) - len(todo), desc="results", unit="run",
              leave=False) as bar:
        for k, outcome in execute([jobs[i] for i in todo], run_job):
            if outcomes[todo[k]] is not None:
                raise RuntimeError(f"the executor returned run {k} twice")
            if outcome.result is not None:
                job = jobs[todo[k]]
                result = replace(outcome.result, seed=job.spec.seed,
                                 provenance=records[job.scene_dir, job.spec.name, job.spec.seed])
                outcome = replace(outcome, result=result, path=write_result(results_dir, result))
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


def _stored(job: Job, expected: Provenance, results_dir: Path, *, keep_stale: bool,
            allow_run: bool, log: Callable[[str], None]) -> Outcome | None:
    """The outcome of ``job`` without running it, or ``None`` if it has to run."""
    scene, spec, protocol = job.scene_dir.name, job.spec, job.protocol
    path = results_dir / result_filename(scene, spec.name, protocol, spec.seed)
    why = ""
    if path.is_file():
        try:
            stored = read_result(path)
        except ValueError as exc:
            why = f"corrupt result file: {exc}"
        else:
            changes = provenance_changes(stored.provenance, expected)
            if not changes:
                return Outcome(scene, spec.name, protocol, "reused", stored, path=path)
            why = "; ".join(str(c) for c in changes)
            if keep_stale:
                log(f"{scene} / {spec.name} / {protocol}: kept although stale ({why})")
                return Outcome(scene, spec.name, protocol, "stale", stored, reason=why,
                               path=path)
    if not allow_run:
        reason = why or f"no result file {path.name} (run without --no-run to compute it)"
        log(f"{scene} / {spec.name} / {protocol}: {reason}")
        return Outcome(scene, spec.name, protocol, "failed", reason=reason, path=path)
    if why:
        log(f"{scene} / {spec.name} / {protocol}: {why}; recomputing")
    return None


def _where(exc: BaseException) -> str:
    """`` (at pkg/module.py:LINE)`` of the innermost frame in this project's code, or ``""``."""
    root = Path(__file__).resolve().parents[2]
    frames = [f for f in traceback.extract_tb(exc.__traceback__)
              if Path(f.filename).resolve().is_relative_to(root)]
    if not frames or frames[-1].filename == __file__:
        return ""
    return f" (at {Path(frames[-1].filename).resolve().relative_to(root)}:{frames[-1].lineno})"

