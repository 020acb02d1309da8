"""Where a neural3d training step goes, and how much faster one variant is than another.

    python bench/neural3d_profile.py parts --scene DIR [--set KEY=VALUE ...] [--threads 2]
        [--warmup 250] [--steps 50] [--device cpu|cuda] [--json FILE]
    python bench/neural3d_profile.py ab --scene DIR --variant 'NAME:KEY=VALUE,...' ...
        [--blocks 7] [--block-steps 10] [--warmup 250] [--threads 1] [--json FILE]

``parts``: the ``fast`` preset's training step (``neural3d.training.step.train_step``,
weight averaging included) after ``--warmup`` untimed steps (the occupancy grid
refreshed from step 0, as in training once under way): iterations per second
over ``--steps`` steps, then the same number of steps under ``torch.profiler``,
broken into the code's ``neural3d.<part>`` profiler labels. A part nested in
another is shown by its path (``sampling > encoding`` is the grid encoding of the
up-sampling's SDF queries); each row is the time inside that label and outside
any label nested in it (ms per step), so the rows add up to the step. The
backward pass is split further by autograd node. The profiler adds some time of
its own: the shares, not the sum, are the figure; it/s is timed without it.
On CUDA a column gives the GPU time of each part.

``ab``: speed of variants of the ``fast`` preset relative to the first, measured
in one process: each variant is warmed up, then blocks of ``--block-steps``
steps alternate between the variants (the order rotates every round) and each
round gives every variant's time relative to the first's; the median over the
rounds is printed, with the range. On a machine shared with other jobs this is
the figure to quote: neighbours slow both variants alike.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from collections import defaultdict
from dataclasses import replace
from pathlib import Path

# Run as a script, this file's folder is sys.path[0]: put the repository root there instead.
sys.path[0] = str(Path(__file__).resolve().parent.parent)

import torch  # noqa: E402
from torch.profiler import ProfilerActivity, profile, record_function  # noqa: E402

from bench.neural3d import training_steps, with_overrides  # noqa: E402
from envelope.atomic import write_json_atomic  # noqa: E402
from envelope.device import resolve_device  # noqa: E402
from neural3d.config import TrainConfig, preset_config  # noqa: E402

LABEL = "neural3d."  # prefix of the training code's profiler labels
STEP_LABEL = "neural3d.step"  # the bench's label around one whole step
_AUTOGRAD_NODE = "autograd::engine::evaluate_function: "
BACKWARD = "backward"
BACKWARD_NODES = 8  # autograd nodes listed under the backward pass


def bench_config(settings: list[str]) -> TrainConfig:
    """The ``fast`` preset with ``settings`` (``key=value``), the grid refreshed from step 0."""
    return replace(with_overrides(preset_config("fast"), settings), occupancy_start=0)


def timed_steps(step, first: int, count: int, device: torch.device) -> tuple[float, float]:
    """(wall s, process CPU s) of ``step(first) .. step(first + count - 1)``."""
    wall, cpu = time.perf_counter(), time.process_time()
    for i in range(first, first + count):
        step(i)
    return time.perf_counter() - wall, time.process_time() - cpu


def _label_path(event) -> tuple[str, ...]:
    """The ``neural3d.`` labels enclosing ``event`` (itself included), outermost first."""
    path = []
    e = event
    while e is not None:
        if e.name.startswith(LABEL) and e.name != STEP_LABEL:
            path.append(e.name[len(LABEL):])
        e = e.cpu_parent
    return tuple(reversed(path))


def _autograd_node(event) -> str | None:
    e = event
    while e is not None:
        if e.name.startswith(_AUTOGRAD_NODE):
            return e.name[len(_AUTOGRAD_NODE):]
        e = e.cpu_parent
    return None


def part_times_us(events, steps: int, device_time: bool) -> dict[str, float]:
    """Microseconds per step of each label path, exclusive of the labels nested in it.

    Time in the step outside every label is ``other``; the backward pass's time is
    also split by autograd node (``backward: <node>``, inclusive of the ops it runs).
    On CUDA, ``device_time`` counts the GPU time of the kernels each op launched;
    backward ops run on autograd's own thread there and are counted as ``backward``.
    """
    def t(e) -> float:
        return e.device_time_total if device_time else e.cpu_time_total

    totals: dict[str, float] = defaultdict(float)
    for e in events:
        if e.name == STEP_LABEL:
            totals["other"] += t(e)
        elif e.name.startswith(LABEL):
            path = _label_path(e)
            totals[" > ".join(path)] += t(e)
            parent = path[:-1]
            totals[" > ".join(parent) if parent else "other"] -= t(e)
        elif e.name.startswith(_AUTOGRAD_NODE):
            path = _label_path(e)
            outer = e.cpu_parent
            if outer is not None and _autograd_node(outer) is not None:
                continue  # a node inside a node: counted with the outer one
            if not path:  # CUDA: the backward ran on autograd's thread
                totals[BACKWARD] += t(e)
            if path and path[-1] != BACKWARD:
                continue  # the eikonal term's first backward: counted in its label
            totals[f"{BACKWARD}: {e.name[len(_AUTOGRAD_NODE):]}"] += t(e)
    return {k: v / steps for k, v in totals.items()}


def parts(args: argparse.Namespace) -> dict:
    device = resolve_device(args.device)
    config = bench_config(args.set)
    step = training_steps(args.scene, config, device)
    for i in range(args.warmup):
        step(i)
    wall_s, cpu_s = timed_steps(step, args.warmup, args.steps, device)
    activities = [ProfilerActivity.CPU] + ([ProfilerActivity.CUDA] if device.type == "cuda"
                                           else [])
    first = args.warmup + args.steps
    with profile(activities=activities) as prof:
        for i in range(first, first + args.steps):
            with record_function(STEP_LABEL):
                step(i)
    events = prof.events()
    cpu = part_times_us(events, args.steps, device_time=False)
    gpu = part_times_us(events, args.steps, device_time=True) if device.type == "cuda" else {}
    step_us = sum(v for k, v in cpu.items() if not k.startswith(f"{BACKWARD}: "))
    nodes = sorted((k for k in cpu if k.startswith(f"{BACKWARD}: ")), key=lambda k: -cpu[k])
    order = [k for k in cpu if not k.startswith(f"{BACKWARD}: ")]
    rows = []
    for key in order:
        rows.append({"part": key, "ms": cpu[key] / 1e3, "share": cpu[key] / step_us,
                     "gpu_ms": gpu.get(key, 0.0) / 1e3 if gpu else None})
        if key == BACKWARD:
            rows += [{"part": f"  {k}", "ms": cpu[k] / 1e3, "share": cpu[k] / step_us,
                      "gpu_ms": gpu.get(k, 0.0) / 1e3 if gpu else None}
                     for k in nodes[:BACKWARD_NODES]]
    print(f"{args.scene.name}, {device}, {torch.get_num_threads()} threads, "
          f"settings {' '.join(args.set) or '(fast preset)'}: "
          f"{args.steps / wall_s:.2f} it/s wall, {args.steps / cpu_s:.2f} it/s per CPU second "
          f"(steps {args.warmup}-{first - 1}, no profiler); parts over steps "
          f"{first}-{first + args.steps - 1} under the profiler, "
          f"{step_us / 1e3:.1f} ms per step there\n")
    gpu_head = " GPU ms |" if gpu else ""
    print(f"| part | ms per step | share |{gpu_head}\n|---|---|---|{'---|' if gpu else ''}")
    for r in rows:
        gpu_cell = f" {r['gpu_ms']:.2f} |" if gpu else ""
        print(f"| {r['part']} | {r['ms']:.2f} | {100 * r['share']:.1f} % |{gpu_cell}")
    return {"scene": str(args.scene), "device": str(device), "threads": torch.get_num_threads(),
            "settings": args.set, "it_per_s": args.steps / wall_s,
            "it_per_cpu_s": args.steps / cpu_s, "parts": rows}


def parse_variant(text: str) -> tuple[str, list[str]]:
    """``'NAME:KEY=VALUE,KEY=VALUE'`` -> (NAME, settings); ``'NAME:'`` is the preset as is."""
    name, sep, rest = text.partition(":")
    if not sep or not name:
        raise ValueError(f"--variant expects NAME:KEY=VALUE,..., got {text!r}")
    return name, [s for s in rest.split(",") if s]


def ab(args: argparse.Namespace) -> dict:
    device = resolve_device(args.device)
    variants = [parse_variant(v) for v in args.variant]
    if len(variants) < 2:
        raise ValueError("ab needs at least two --variant (the first is the reference)")
    steps = {}
    for name, settings in variants:
        steps[name] = training_steps(args.scene, bench_config(settings), device)
        for i in range(args.warmup):
            steps[name](i)
    names = [n for n, _ in variants]
    wall: dict[str, list[float]] = {n: [] for n in names}
    cpu: dict[str, list[float]] = {n: [] for n in names}
    for r in range(args.blocks):
        first = args.warmup + r * args.block_steps
        for name in names[r % len(names):] + names[:r % len(names)]:
            w, c = timed_steps(steps[name], first, args.block_steps, device)
            wall[name].append(w)
            cpu[name].append(c)
    ref = names[0]
    rows = []
    print(f"{args.scene.name}, {device}, {torch.get_num_threads()} threads, {args.blocks} rounds "
          f"of {args.block_steps} steps after {args.warmup}\n")
    print("| variant | settings | it/s (median) | time / reference (median, range) | "
          "CPU time / reference |\n|---|---|---|---|---|")
    for name, settings in variants:
        ratios = [a / b for a, b in zip(wall[name], wall[ref])]
        cpu_ratios = [a / b for a, b in zip(cpu[name], cpu[ref])]
        row = {"variant": name, "settings": settings,
               "it_per_s": args.block_steps / statistics.median(wall[name]),
               "ratio": statistics.median(ratios), "ratio_min": min(ratios),
               "ratio_max": max(ratios), "cpu_ratio": statistics.median(cpu_ratios)}
        rows.append(row)
        print(f"| {name} | {' '.join(settings) or '(fast preset)'} | {row['it_per_s']:.2f} | "
              f"{row['ratio']:.3f} ({row['ratio_min']:.3f}-{row['ratio_max']:.3f}) | "
              f"{row['cpu_ratio']:.3f} |", flush=True)
    return {"scene": str(args.scene), "device": str(device), "threads": torch.get_num_threads(),
            "blocks": args.blocks, "block_steps": args.block_steps, "variants": rows}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    pp = sub.add_parser("parts", help="ms per part of one training step, and it/s")
    pp.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="override a fast-preset field (model.KEY for the field)")
    pp.add_argument("--steps", type=int, default=50, help="timed and profiled steps (50)")
    ap = sub.add_parser("ab", help="speed of variants relative to the first, interleaved")
    ap.add_argument("--variant", action="append", default=[], metavar="NAME:KEY=VALUE,...",
                    help="a variant of the fast preset; the first is the reference "
                         "(e.g. 'base:' and 'fd:model.normals=finite_difference')")
    ap.add_argument("--blocks", type=int, default=7, help="rounds of blocks (7)")
    ap.add_argument("--block-steps", type=int, default=10, help="steps per block (10)")
    for p in (pp, ap):
        p.add_argument("--scene", type=Path, required=True, help="a scene folder")
        p.add_argument("--warmup", type=int, default=250,
                       help="untimed steps first, so the occupancy grid is refreshed (250)")
        p.add_argument("--threads", type=int, default=None, help="torch CPU threads")
        p.add_argument("--device", default="cpu", help="cpu (default), cuda or cuda:N")
        p.add_argument("--json", type=Path, default=None, help="also write the figures here")
    args = parser.parse_args(argv)
    if args.threads is not None:
        torch.set_num_threads(args.threads)
    try:
        figures = parts(args) if args.command == "parts" else ab(args)
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if args.json:
        write_json_atomic(args.json, figures)
    return 0


if __name__ == "__main__":
    sys.exit(main())
