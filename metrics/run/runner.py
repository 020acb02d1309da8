"""Run only the missing (scene, method, protocol) results; reuse the ones already on disk.

Results are keyed by their provenance record (:mod:`envelope.provenance`): the
method's config, the fingerprint of the code it depends on, the scene's
fingerprint (its ``transforms.json``, which records how it was rendered) and
library versions. A stored result is reused only when its record equals the
one the current code would write (:func:`expected_provenance`); otherwise the
log says which part changed and the method runs again, unless ``reuse_stale``
keeps it on purpose (its outcome is then ``"stale"`` and the tables mark it).
Results are written with :func:`envelope.results.write_result`, carrying the
record, and the config and seed of their :class:`MethodSpec` (what the method itself put
there is replaced: the spec is the one record of how it ran). A method that raises is
recorded as a failed outcome with its reason; the other runs go on.

The runs that are missing go to an executor (:data:`Execute`): here, one
after the other in this process (:func:`execute_local`); on a Ray cluster
with :mod:`metrics.run.executors`. Either way only this process writes the
result files, as each run comes back.
"""

from __future__ import annotations

import time
import traceback
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, fields, is_dataclass, replace
from functools import partial
from pathlib import Path
from typing import Any, Literal

from tqdm import tqdm

from envelope.executors.ray_tasks import TaskResources
from envelope.method import Method
from envelope.method_input import MethodInput
from envelope.provenance import (
    Provenance,
    file_fingerprint,
    make_provenance,
    provenance_changes,
)
from envelope.results import MethodResult, read_result, result_filename, write_result
from envelope.scenes.scene import read_method_input

RunFn = Callable[[Path, str], MethodResult]
"""(scene folder, protocol) -> the method's result for that scene; may raise."""
OutcomeStatus = Literal["reused", "stale", "ran", "failed"]
"""``stale``: a stored result whose provenance differs from the current one, kept on purpose."""


@dataclass(frozen=True)
class MethodSpec:
    """A method as the comparison runs it: its :class:`envelope.method.Method` bound to a config.

    ``method``: what the method declares (its name, protocols, resources, code, ...);
    ``method_config``: the config it runs with (an instance of ``method.config_type``);
    ``protocols``: those it runs on in this comparison; ``run(scene folder, protocol)``: the
    method bound to its config, reading the folder as its
    :class:`~envelope.method_input.MethodInput` (:func:`metrics.run.methods.spec_from_method`).
    ``artefacts_dir``: where ``run`` writes a folder per scene (named by the scene) that the
    comparison keeps (a trained method's run folder); such a ``run`` also takes an
    ``artefacts_dir=`` keyword to write it elsewhere (a worker on another machine).
    ``conditions``: what the comparison changed about the method's inputs (degraded images,
    predicted masks), recorded in :attr:`config` beside the method's own config.

    The rest is read off the method and its config (properties): :attr:`config`, the config
    as every result of this spec records it and as its provenance keys it; :attr:`seed`, the
    config's training seed (specs that differ only by it keep their results side by side,
    ``__seed<k>`` files); :attr:`code` and :attr:`libraries`, what goes into each result's
    provenance; :attr:`resources`, what one run reserves; and the method's name,
    ``has_footprint``, ``paper_name``, ``heavy``, ``mesh_file`` and ``debug_images``.
    A method given as a function of a scene folder gets its spec from :func:`folder_spec`.
    """

    method: Method
    method_config: Any
    protocols: tuple[str, ...]
    run: RunFn
    artefacts_dir: Path | None = None
    conditions: Mapping[str, Any] = field(default_factory=dict)

    @property
    def name(self) -> str:
        return self.method.name

    @property
    def config(self) -> dict[str, Any]:
        """The config as its results record it: the method's record of its config
        (:meth:`envelope.method.Method.config_record`), then the :attr:`conditions`."""
        return {**self.method.config_record(self.method_config), **self.conditions}

    @property
    def seed(self) -> int | None:
        return config_seed(self.method_config)

    @property
    def code(self) -> tuple[str, ...]:
        """The packages whose source the results depend on: the core and the method's own."""
        return ("envelope", *self.method.packages)

    @property
    def libraries(self) -> tuple[str, ...]:
        return self.method.libraries

    @property
    def resources(self) -> TaskResources:
        cpus, gpus = self.method.cpus_gpus(self.method_config)
        return TaskResources(cpus=cpus, gpus=gpus)

    @property
    def has_footprint(self) -> bool:
        return self.method.has_footprint

    @property
    def paper_name(self) -> str | None:
        return self.method.paper_name

    @property
    def heavy(self) -> bool:
        return self.method.heavy

    @property
    def mesh_file(self) -> str | None:
        return self.method.mesh_file

    @property
    def debug_images(self) -> Callable[[Path, str, Path], None] | None:
        """``(scene folder, protocol, folder)``: write the method's pipeline images of the
        scene into ``folder``; ``None`` if the method has none."""
        if self.method.debug_images is None:
            return None
        return partial(_debug_images_of_folder, self.method, self.method_config)


def config_seed(config: Any) -> int | None:
    """The ``seed`` field of a dataclass config (neural3d's training seed), else ``None``."""
    if is_dataclass(config) and any(f.name == "seed" for f in fields(config)):
        return config.seed
    return None


def run_on_folder(method: Method, config: Any, scene_dir: Path, protocol: str,
                  **artefacts_dir: Path) -> MethodResult:
    """``method`` run with ``config`` on the scene folder read as its
    :class:`~envelope.method_input.MethodInput` (the inputs it declares, never the truth)."""
    return method.run(read_method_input(scene_dir, method.inputs), protocol, config,
                      **artefacts_dir)


def _debug_images_of_folder(method: Method, config: Any, scene_dir: Path, protocol: str,
                            folder: Path) -> None:
    assert method.debug_images is not None
    method.debug_images(read_method_input(scene_dir, method.inputs), protocol, config, folder)


def folder_spec(name: str, protocols: Sequence[str], config: Any, run: RunFn, *,
                packages: tuple[str, ...] = ()) -> MethodSpec:
    """The spec of a method given as ``run(scene folder, protocol)`` (a test's or a
    benchmark script's stand-in): its :class:`~envelope.method.Method` declares ``protocols``,
    a config of ``config``'s type (a dict is recorded as it is) and ``packages`` as its code,
    and reads the folder it is given."""
    method = Method(name=name, inputs=(), protocols=tuple(protocols),  # type: ignore[arg-type]
                    config_type=type(config), run=partial(_on_root, run), packages=packages)
    return MethodSpec(method, config, tuple(protocols), run)


def _on_root(run: RunFn, scene: MethodInput, protocol: str, config: Any,
             **artefacts_dir: Path) -> MethodResult:
    return run(scene.root, protocol, **artefacts_dir)


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
                result = replace(outcome.result, config=job.spec.config, seed=job.spec.seed,
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
    if (result.scene, result.method) != (scene, spec.name):  # they name the result file
        result = replace(result, scene=scene, method=spec.name)
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

