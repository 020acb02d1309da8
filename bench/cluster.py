"""The comparison on a local Ray vs here, Ray's cost per task, and a projection to N nodes.

    python bench/cluster.py                                   # 2D methods on the tiny preset
    python bench/cluster.py --methods 2D-S,2D-SS,neural3d --neural3d-steps 100 \\
        --out docs/cluster_bench.md

Three measurements, printed as Markdown (and written to ``--out``):

1. The comparison (``metrics.compare.compare``, fresh results folder each
   time) with ``--executor local`` and with ``--executor ray`` on a Ray
   started here with ``--cpus`` cores: wall times, their ratio, and Ray's
   start-up time (given apart: a cluster is started once for many runs).
2. Ray's cost per task: jobs of a method that does nothing, each still packing
   its scene, sending it through the object store, unpacking it on a worker
   and returning a result; one at a time (latency) and all at once (cost per
   task at full throughput, core-seconds).
3. A projection for a study of ``--buildings`` buildings on N nodes of
   ``--node-cpus`` cores: the per-task times measured in 1 (each plus Ray's
   cost from 2) repeated over the buildings and scheduled longest first on the
   cores (each task holding the cores its method asks for). It assumes the
   nodes are as fast as this machine and that scene transfer stays small
   next to the tasks (true for 2D methods on small scenes only).

The tiny preset is rendered into a temporary folder at the built-in default's
size (``dataset.benchmark_cache.DefaultBenchmark``), unless ``--data`` is given.
"""

from __future__ import annotations

import argparse
import heapq
import math
import os
import statistics
import sys
import tempfile
import time
import warnings
from pathlib import Path

sys.path[0] = str(Path(__file__).resolve().parent.parent)

from dataset.benchmark_cache import DefaultBenchmark  # noqa: E402
from dataset.generate import GenerateConfig, generate_preset  # noqa: E402
from envelope.atomic import write_text_atomic  # noqa: E402
from envelope.executors.ray_tasks import LOCAL_ONLY_ENV, RayConfig, ray_session  # noqa: E402
from envelope.protocols import DEFAULT_PROTOCOLS  # noqa: E402
from envelope.results import MethodResult  # noqa: E402
from envelope.scenes.scene import find_scene_folders  # noqa: E402
from metrics.comparison import compare  # noqa: E402
from metrics.run.executors import make_executor  # noqa: E402
from metrics.run.methods import method_specs  # noqa: E402
from metrics.run.runner import (  # noqa: E402
    Job,
    MethodSpec,
    folder_spec,
    run_job,
    run_missing,
)
from neural3d.method import Neural3dBudget  # noqa: E402

NODES = (1, 2, 4, 8, 16, 32, 64)


def _noop_spec() -> MethodSpec:
    def run(scene_dir: Path, protocol: str) -> MethodResult:
        return MethodResult(scene_dir.name, "noop", protocol, None, None, None)

    return folder_spec("noop", ("ideal",), {}, run)


def time_comparisons(data: Path, specs_for, tmp: Path, ray: RayConfig) -> dict:
    """Wall times of the comparison, local then on Ray (start-up apart), and per-task times."""
    import ray as ray_module

    start = time.perf_counter()
    local = compare(data, specs_for(tmp / "r-local"), tmp / "r-local", tmp / "o-local",
                    command="bench/cluster.py")
    t_local = time.perf_counter() - start
    start = time.perf_counter()
    with ray_session(ray):
        t_start = time.perf_counter() - start
        start = time.perf_counter()
        remote = compare(data, specs_for(tmp / "r-ray"), tmp / "r-ray", tmp / "o-ray",
                         command="bench/cluster.py", execute=make_executor("ray", ray))
        t_ray = time.perf_counter() - start
        overhead = time_overhead(data, tmp)
        cpus = ray_module.cluster_resources().get("CPU", 0.0)
    failed = [o for o in (*local.outcomes, *remote.outcomes) if o.status != "ran"]
    tasks = [(o.method, o.result.wall_time_s) for o in local.outcomes if o.result is not None]
    return {"local_s": t_local, "ray_s": t_ray, "ray_start_s": t_start, "failed": len(failed),
            "tasks": tasks, "cpus": cpus, **overhead}


def time_overhead(data: Path, tmp: Path, repeat: int = 5) -> dict:
    """Seconds per no-op job through the Ray executor: alone (latency) and many at once."""
    scenes = find_scene_folders(data)
    spec = _noop_spec()
    execute = make_executor("ray", RayConfig())
    latencies = []
    for k in range(repeat):
        start = time.perf_counter()
        run_missing(scenes[:1], [spec], tmp / f"noop-{k}", log=lambda _: None, execute=execute)
        latencies.append(time.perf_counter() - start)
    many = scenes * 10
    jobs = [Job(s, spec, "ideal") for s in many]
    start = time.perf_counter()
    outcomes = list(execute(jobs, run_job))
    t_many = time.perf_counter() - start
    assert len(outcomes) == len(jobs)
    return {"latency_s": statistics.median(latencies), "throughput_s": t_many / len(jobs),
            "throughput_tasks": len(jobs),
            "scene_mb": sum(_size(s) for s in scenes) / len(scenes) / 2**20}


def _size(folder: Path) -> int:
    return sum(p.stat().st_size for p in folder.rglob("*") if p.is_file())


def project(tasks: list[tuple[float, float]], nodes: int, node_cpus: int) -> float:
    """Makespan (s) of ``tasks`` = [(seconds, cores)] scheduled longest first on ``nodes``
    nodes of ``node_cpus`` cores: each core is a slot; a task of c cores takes c slots of
    one node (greedy: the node whose c-th earliest slot frees first)."""
    free = [[0.0] * node_cpus for _ in range(nodes)]
    for seconds, cores in sorted(tasks, reverse=True):
        c = max(1, min(node_cpus, math.ceil(cores)))
        best = min(range(nodes), key=lambda n: heapq.nsmallest(c, free[n])[-1])
        slots = sorted(free[best])
        begin = slots[c - 1]
        free[best] = [begin + seconds] * c + slots[c:]
    return max(max(f) for f in free)


def report(m: dict, methods: tuple[str, ...], specs: list[MethodSpec], buildings: int,
           node_cpus: int, n_scenes: int, load: str) -> str:
    cores = {s.name: s.resources.cpus for s in specs}
    # Ray's cost of one task in core-seconds: wall per task at full throughput x busy cores.
    overhead_s = m["throughput_s"] * m["cpus"]
    per_building = [(t + overhead_s, cores[name]) for name, t in m["tasks"]]
    study = [per_building[i % len(per_building)] for i in range(len(per_building) * buildings
                                                                // n_scenes)]
    cpu_s = sum(t * c for t, c in study)
    lines = [
        "# Cluster benchmark (bench/cluster.py)", "",
        f"Machine: {os.cpu_count()} cores, **shared with other jobs while measured** "
        f"(load average {load}); wall times vary with the neighbours, task counts do not.",
        f"Methods {', '.join(methods)} on {n_scenes} scenes "
        f"({len(m['tasks'])} tasks, mean scene {m['scene_mb']:.1f} MiB packed); "
        f"Ray {_ray_version()} started here with {m['cpus']:g} CPUs.", "",
        "| run | wall s |", "|---|---|",
        f"| comparison, `--executor local` (one task after the other) | {m['local_s']:.1f} |",
        f"| comparison, `--executor ray` (Ray already running) | {m['ray_s']:.1f} |",
        f"| Ray start-up (`ray.init`, once per run of the CLI) | {m['ray_start_s']:.1f} |",
        f"| ratio ray / local (without start-up) | {m['ray_s'] / m['local_s']:.2f} |",
        f"| ratio ray / local (with start-up, as the CLI runs it) | "
        f"{(m['ray_s'] + m['ray_start_s']) / m['local_s']:.2f} |", "",
        "Ray's cost per task (a method that does nothing; the scene is still packed, sent, "
        "unpacked and a result returned):", "",
        "| measure | s per task |", "|---|---|",
        f"| one job alone, driver to driver (median of 5) | {m['latency_s']:.3f} |",
        f"| {m['throughput_tasks']} jobs at once, wall / jobs | {m['throughput_s']:.3f} |",
        f"| the same in core-seconds (x {m['cpus']:g} cores; used in the projection) | "
        f"{overhead_s:.3f} |", "",
        f"Projection: {buildings} buildings (the measured tasks repeated, "
        f"{len(study)} tasks, {cpu_s / 3600:.2f} core-hours incl. Ray's cost), nodes of "
        f"{node_cpus} cores as fast as this one, scheduled longest task first:", "",
        "| nodes | projected wall | speed-up vs 1 node |", "|---|---|---|",
    ]
    one = project(study, 1, node_cpus)
    for n in NODES:
        t = project(study, n, node_cpus)
        lines.append(f"| {n} | {_duration(t)} | {one / t:.1f} |")
    return "\n".join(lines) + "\n"


def _duration(seconds: float) -> str:
    if seconds < 120:
        return f"{seconds:.1f} s"
    if seconds < 7200:
        return f"{seconds / 60:.1f} min"
    return f"{seconds / 3600:.1f} h"


def _ray_version() -> str:
    import ray

    return ray.__version__


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--data", type=Path, help="benchmark folder (default: tiny preset, rendered)")
    p.add_argument("--methods", default="2D-S,2D-SS", help="comma-separated (default 2D-S,2D-SS)")
    p.add_argument("--neural3d-steps", type=int, default=100,
                   help="neural3d training steps per building (default 100)")
    p.add_argument("--cpus", type=int, default=os.cpu_count(),
                   help="cores of the local Ray (default: all)")
    p.add_argument("--buildings", type=int, default=500, help="buildings of the projected study")
    p.add_argument("--node-cpus", type=int, default=16, help="cores per projected node")
    p.add_argument("--out", type=Path, help="also write the Markdown here")
    args = p.parse_args(argv)
    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
    os.environ.setdefault(LOCAL_ONLY_ENV, "0")
    methods = tuple(m.strip() for m in args.methods.split(",") if m.strip())
    budget = Neural3dBudget(preset="tiny", steps=args.neural3d_steps, resolution=64,
                            eval_frames=1)

    def specs_for(results: Path) -> list[MethodSpec]:
        return method_specs(methods, DEFAULT_PROTOCOLS, results, configs={"neural3d": budget})

    with tempfile.TemporaryDirectory(prefix="cluster-bench-") as tmp:
        tmp = Path(tmp)
        data = args.data
        if data is None:
            d = DefaultBenchmark()
            data = tmp / "tiny"
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", UserWarning)
                generate_preset("tiny", data, GenerateConfig(resolution=d.resolution,
                                                             views=d.views), progress=False)
        measured = time_comparisons(data, specs_for, tmp, RayConfig(num_cpus=args.cpus))
        load = " / ".join(f"{x:.1f}" for x in os.getloadavg())
        text = report(measured, methods, specs_for(tmp / "r"), args.buildings, args.node_cpus,
                      len(find_scene_folders(data)), load)
    if measured["failed"]:
        text += f"\n**{measured['failed']} runs failed**; the figures above are not comparable.\n"
    print(text)
    if args.out:
        write_text_atomic(args.out, text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
