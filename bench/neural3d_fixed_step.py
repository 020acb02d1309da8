"""Steps per second of today's neural3d training step and of the fixed-shape step.

    python bench/neural3d_fixed_step.py --scene DIR [--buffer N ...] [--set KEY=VALUE ...]
        [--warmup 250] [--blocks 5] [--block-steps 10] [--threads N] [--device cpu|cuda]
        [--json FILE]

The ``fast`` preset's training step (``neural3d.training.step.train_step``, weight
averaging included; ``--set`` changes a field of the preset) as it is, and with
``sample_buffer`` set to each ``--buffer`` (the fixed-shape step,
``neural3d.rendering.fixed_shape``), each on a fresh field of the same seed. Every
variant is warmed up for ``--warmup`` steps (the occupancy grid refreshed from step
0, as in training once under way), then blocks of ``--block-steps`` steps alternate
between the variants (the order rotates every round) as in
``bench/neural3d_profile.py ab``: the median over the rounds of each variant's time
relative to today's is the figure to quote on a shared machine. Per variant it also
gives, over the timed steps, the field points evaluated with the gradient per step
(today: the samples kept; fixed: the slots), the candidates among them and the
candidates dropped for want of a slot.

The steps run eagerly on every device: capturing the fixed-shape step as a CUDA graph
(what it is for) is not done yet; on CUDA each step is synchronised before the clock
is read.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from dataclasses import replace
from pathlib import Path

# Run as a script, this file's folder is sys.path[0]: put the repository root there instead.
sys.path[0] = str(Path(__file__).resolve().parent.parent)

import torch  # noqa: E402

from bench.neural3d import training_state  # noqa: E402
from bench.neural3d_profile import bench_config  # noqa: E402
from bench.tables import markdown_table  # noqa: E402
from envelope.atomic import write_json_atomic  # noqa: E402
from envelope.device import resolve_device  # noqa: E402
from neural3d.training.step import StepResult  # noqa: E402

TODAY = "today"


def sample_counts(result: StepResult) -> tuple[int, int, int]:
    """(field points evaluated, candidates among them, candidates dropped) of one step."""
    render = result.render
    points = len(render.sdf_gradients)
    mask = render.sdf_gradient_mask
    kept = points if mask is None else int(mask.sum())
    return points, kept, result.dropped_samples


def run(args: argparse.Namespace) -> dict:
    device = resolve_device(args.device)
    if any(n <= 0 for n in args.buffer):
        raise ValueError(f"--buffer takes slot counts > 0, got {args.buffer}")
    base = bench_config(args.set)
    if base.sample_buffer:
        raise ValueError("the reference is today's step: do not --set sample_buffer")
    variants = {TODAY: base} | {f"fixed {n}": replace(base, sample_buffer=n)
                                for n in args.buffer}
    states = {}
    for name, config in variants.items():
        states[name] = training_state(args.scene, config, device)
        for i in range(args.warmup):
            states[name].step(i)
    names = list(variants)
    wall: dict[str, list[float]] = {n: [] for n in names}
    counts: dict[str, list[tuple[int, int, int]]] = {n: [] for n in names}
    for r in range(args.blocks):
        first = args.warmup + r * args.block_steps
        for name in names[r % len(names):] + names[:r % len(names)]:
            tic = time.perf_counter()
            for i in range(first, first + args.block_steps):
                result = states[name].step(i)
                if device.type == "cuda":
                    torch.cuda.synchronize(device)
                counts[name].append(sample_counts(result))
            wall[name].append(time.perf_counter() - tic)
    rows = []
    for name in names:
        ratios = [a / b for a, b in zip(wall[name], wall[TODAY])]
        points, kept, dropped = (statistics.fmean(c) for c in zip(*counts[name]))
        rows.append({"variant": name, "sample_buffer": variants[name].sample_buffer,
                     "it_per_s": args.block_steps / statistics.median(wall[name]),
                     "ratio": statistics.median(ratios), "ratio_min": min(ratios),
                     "ratio_max": max(ratios), "points_per_step": points,
                     "candidates_per_step": kept + dropped, "dropped_per_step": dropped})
    print(f"{args.scene.name}, {device}, {torch.get_num_threads()} threads, {args.blocks} "
          f"rounds of {args.block_steps} steps after {args.warmup}, settings "
          f"{' '.join(args.set) or '(fast preset)'}\n")
    print(markdown_table(
        "Today's step and the fixed-shape step",
        ["step", "it/s (median)", "time / today (median, range)", "field points a step",
         "candidates a step", "dropped a step"],
        [[r["variant"], f"{r['it_per_s']:.2f}",
          f"{r['ratio']:.3f} ({r['ratio_min']:.3f}-{r['ratio_max']:.3f})",
          f"{r['points_per_step']:.0f}", f"{r['candidates_per_step']:.0f}",
          f"{r['dropped_per_step']:.0f}"] for r in rows]))
    return {"scene": str(args.scene), "device": str(device), "threads": torch.get_num_threads(),
            "settings": args.set, "warmup": args.warmup, "blocks": args.blocks,
            "block_steps": args.block_steps, "variants": rows}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scene", type=Path, required=True, help="a scene folder")
    parser.add_argument("--buffer", type=int, nargs="+", default=[8192, 12288],
                        help="sample slots of the fixed-shape variants (default 8192 12288; "
                             "a fast batch has 512 x 31 = 15872 samples)")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="override a fast-preset field (model.KEY for the field)")
    parser.add_argument("--warmup", type=int, default=250,
                        help="untimed steps first, so the occupancy grid is refreshed (250)")
    parser.add_argument("--blocks", type=int, default=5, help="rounds of blocks (5)")
    parser.add_argument("--block-steps", type=int, default=10, help="steps per block (10)")
    parser.add_argument("--threads", type=int, default=None, help="torch CPU threads")
    parser.add_argument("--device", default="cpu", help="cpu (default), cuda or cuda:N")
    parser.add_argument("--json", type=Path, default=None, help="also write the figures here")
    args = parser.parse_args(argv)
    if args.threads is not None:
        torch.set_num_threads(args.threads)
    try:
        if not (args.scene / "transforms.json").is_file():
            raise ValueError(f"{args.scene} is not a scene folder (no transforms.json)")
        figures = run(args)
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if args.json:
        write_json_atomic(args.json, figures)
    return 0


if __name__ == "__main__":
    sys.exit(main())
