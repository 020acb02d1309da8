"""Where the comparison's missing runs execute: here, one after the other (``local``); here,
several at once in processes of their own (``processes``); or on a Ray cluster (``ray``).
``auto`` picks ``processes`` when two heavy runs fit at once, else ``local``.

All are :data:`metrics.run.runner.Execute` functions: they take the jobs and the
function that runs one (:func:`metrics.run.runner.run_job`) and yield each
outcome as it finishes; :func:`metrics.run.runner.run_missing` writes the result
files. ``processes`` runs the light methods' jobs (those not ``heavy``: the 2D
methods take milliseconds) here first, then the heavy ones (neural3d's trainings)
in spawned processes, as many at once as their ``resources`` fit in this
machine's cores and GPUs (:mod:`envelope.executors.process_tasks`): two
one-thread trainings side by side on two cores, or eight on one GPU when each
reserves an eighth of it. A heavy job whose process dies is recorded as a
failed run; the others go on. ``ray`` makes one Ray task per (scene, method,
protocol) and assumes no shared file system: each scene folder is packed once into the object store
and unpacked by the worker into a temporary folder; the outcome and the
method's artefacts folder (a trained method's run folder, with its mesh
and footprint) come back, and this process alone writes them,
atomically. Each task reserves its spec's ``resources``; a task whose worker
dies is re-run up to ``RayConfig.max_retries`` times and then recorded as a
failed run, like a method that fails on its input (which is not re-run).
"""

from __future__ import annotations

import tempfile
from collections.abc import Iterator, Sequence
from dataclasses import replace
from functools import partial
from pathlib import Path

from envelope.atomic import atomic_directory
from envelope.executors.folder_pack import pack_folder, unpack_folder
from envelope.executors.process_tasks import Capacity, machine_capacity, run_in_processes
from envelope.executors.ray_tasks import (
    EXECUTORS,
    ExecutorName,
    RayConfig,
    TaskLost,
    TaskResources,
    ray_session,
    run_tasks,
)
from envelope.method import artefacts_folder
from metrics.run.runner import Execute, Job, Outcome, RunOne, execute_local


def make_executor(name: ExecutorName, ray: RayConfig | None = None,
                  cpus: int | None = None) -> Execute:
    """The executor called ``name``; ``ray`` says where a ``ray`` executor's tasks run
    (default: a Ray started on this machine), ``cpus`` how many cores a ``processes``
    executor's runs may fill at once (default: this machine's; its GPUs are counted).

    Raises
    ------
    ValueError
        If ``name`` is not an executor.
    """
    if name == "auto":
        return partial(execute_auto, cpus=cpus)
    if name == "local":
        return execute_local
    if name == "processes":
        return partial(execute_processes, cpus=cpus)
    if name == "ray":
        return partial(execute_ray, config=ray if ray is not None else RayConfig())
    raise ValueError(f"unknown executor {name!r}; choose from {', '.join(EXECUTORS)}")


def execute_auto(jobs: Sequence[Job], run_one: RunOne, *, cpus: int | None = None
                 ) -> Iterator[tuple[int, Outcome]]:
    """:func:`execute_processes` when two or more heavy jobs are to run and two of them fit
    at once in this machine (``cpus`` cores, or all of them, and its GPU): one-thread
    trainings on two cores, or trainings sharing a GPU; else :func:`execute_local`."""
    heavy = [j.spec.resources for j in jobs if j.spec.heavy]
    if len(heavy) >= 2:
        capacity = _capacity(heavy, cpus)
        if min(r.cpus for r in heavy) * 2 <= capacity.cpus and (
                min(r.gpus for r in heavy) * 2 <= capacity.gpus + 1e-9):
            yield from execute_processes(jobs, run_one, cpus=cpus)
            return
    yield from execute_local(jobs, run_one)


def execute_processes(jobs: Sequence[Job], run_one: RunOne, *, cpus: int | None = None
                      ) -> Iterator[tuple[int, Outcome]]:
    """Run the light jobs here, one after the other, then the heavy ones each in a spawned
    process, as many at once as their ``spec.resources`` fit in ``cpus`` cores (default:
    this machine's) and its GPU if a job reserves one; yield ``(index, outcome)`` as they
    finish. A heavy job that raises, or whose process dies, is a failed outcome.
    """
    heavy = [i for i, j in enumerate(jobs) if j.spec.heavy]
    for i, job in enumerate(jobs):
        if not job.spec.heavy:
            yield i, run_one(job)
    if not heavy:
        return
    calls = [((jobs[i],), jobs[i].spec.resources) for i in heavy]
    capacity = _capacity([resources for _, resources in calls], cpus)
    for k, value in run_in_processes(run_one, calls, capacity):
        job = jobs[heavy[k]]
        if isinstance(value, TaskLost):
            value = Outcome(job.scene_dir.name, job.spec.name, job.protocol, "failed",
                            reason=f"its process failed: {value.reason}")
        yield heavy[k], value


def _capacity(reserved: Sequence[TaskResources], cpus: int | None) -> Capacity:
    """This machine's capacity for runs that reserve ``reserved`` (its GPU counted only if
    one of them reserves a share of it, so that torch is imported only then)."""
    return machine_capacity(cpus, count_gpus=any(r.gpus for r in reserved))


def execute_ray(
    jobs: Sequence[Job], run_one: RunOne, *, config: RayConfig
) -> Iterator[tuple[int, Outcome]]:
    """Run every job as a Ray task; yield ``(index, outcome)`` as tasks finish.

    A job's artefacts folder is unpacked where the method keeps it
    (:func:`envelope.method.artefacts_folder` under ``spec.artefacts_dir``, replacing the one
    there) before its outcome is yielded. Leaving the iteration early (Ctrl-C) cancels the
    tasks not yet collected.
    """
    if not jobs:
        return
    with ray_session(config):
        import ray

        # One object per scene, shared by all of its jobs (the driver's folders are not read
        # again: a worker never needs them).
        scenes = {d: ray.put(pack_folder(d)) for d in dict.fromkeys(j.scene_dir for j in jobs)}
        calls = [((scenes[j.scene_dir], j, run_one), j.spec.resources) for j in jobs]
        for i, value in run_tasks(_run_packed, calls, max_retries=config.max_retries):
            job = jobs[i]
            if isinstance(value, TaskLost):
                yield i, Outcome(job.scene_dir.name, job.spec.name, job.protocol, "failed",
                                 reason=f"Ray task lost: {value.reason}")
                continue
            outcome, artefacts = value
            if artefacts is not None and job.spec.artefacts_dir is not None:
                with atomic_directory(artefacts_folder(job.spec.artefacts_dir,
                                                       job.scene_dir.name, job.protocol)) as tmp:
                    unpack_folder(artefacts, tmp)
            yield i, outcome


def _run_packed(scene_tar: bytes, job: Job, run_one: RunOne) -> tuple[Outcome, bytes | None]:
    """On a worker: unpack the scene into a temporary folder, run the job there, and return
    its outcome with its artefacts folder packed (``None`` if the method wrote none)."""
    with tempfile.TemporaryDirectory(prefix="envelope-bench-") as tmp:
        scene_dir = unpack_folder(scene_tar, Path(tmp) / "scene" / job.scene_dir.name)
        artefacts = Path(tmp) / "artefacts" if job.spec.artefacts_dir is not None else None
        outcome = run_one(replace(job, scene_dir=scene_dir, artefacts_dir=artefacts))
        kept = (artefacts_folder(artefacts, scene_dir.name, job.protocol)
                if artefacts is not None else None)
        return outcome, pack_folder(kept) if kept is not None and kept.is_dir() else None
