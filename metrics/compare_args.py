"""The command line of ``python -m metrics.compare``: its options, their help and defaults."""

from __future__ import annotations

import argparse
from collections.abc import Mapping, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

from dataset.core.cli_errors import add_debug_flag
from dataset.core.protocols import VIEW_PROTOCOLS
from dataset.degrade.spec import DEGRADATIONS
from dataset.executors.ray_tasks import add_executor_arguments
from metrics.benchmark_cache import DEFAULT_CACHE, DefaultBenchmark
from metrics.methods import METHODS
from neural3d.method import Neural3dBudget


def parse_compare_args(argv: Sequence[str] | None) -> argparse.Namespace:
    """The options of ``python -m metrics.compare`` (``--help`` explains each)."""
    parser = argparse.ArgumentParser(
        prog="python -m metrics.compare",
        description=(
            "Compare WWR / window / facade-area and footprint estimates of 2D-S, 2D-SS and "
            "neural3d against ground truth, running only the results that are missing. "
            "Without --data it runs the built-in default: the tiny benchmark (generated into "
            f"{DEFAULT_CACHE}), all methods, about {DefaultBenchmark.expected_minutes:g} "
            "minutes on 2 CPU cores. Prints Table 2 "
            "(errors per family) and Table 3 (footprint IoU) and writes them as CSV, Markdown "
            "and LaTeX with plots and provenance.json into --out."
        ),
    )
    parser.add_argument("--data", type=Path, help="a scene folder or a folder of scene folders "
                        "(default: the built-in tiny benchmark)")
    parser.add_argument("--methods", default=",".join(METHODS),
                        help=f"comma-separated methods (default: {','.join(METHODS)})")
    parser.add_argument("--views", default=",".join(VIEW_PROTOCOLS),
                        help="comma-separated view protocols of the 2D methods "
                        "(default: ideal,multi); neural3d always uses its train views")
    parser.add_argument("--results", type=Path,
                        help="folder of result JSONs to read and fill (default: <data>-results)")
    parser.add_argument("--out", type=Path,
                        help="folder for tables, plots, provenance (default: <data>-compare)")
    parser.add_argument("--neural3d-steps", type=int,
                        help="training steps per building for neural3d: the budget that fixes "
                        "its result (default: the preset's own; the built-in default run uses "
                        f"{DefaultBenchmark.neural3d_steps})")
    parser.add_argument("--neural3d-max-minutes", type=float, default=Neural3dBudget.max_minutes,
                        help="safety cap on neural3d's training time per building, minutes; a "
                        "run it stops is marked 'cut short' in every table "
                        f"(default: {Neural3dBudget.max_minutes:g})")
    parser.add_argument("--neural3d-threads", type=int, default=Neural3dBudget.threads,
                        help="torch CPU threads for neural3d (recorded with the result; "
                        f"default: {Neural3dBudget.threads})")
    parser.add_argument("--neural3d-preset", default=Neural3dBudget.preset,
                        choices=("paper", "fast", "tiny"), help="neural3d training preset")
    parser.add_argument("--neural3d-resolution", type=int,
                        help="marching-cubes samples along the scene box's longest side "
                        "(default: neural3d's own; the built-in default run uses "
                        f"{DefaultBenchmark.neural3d_resolution})")
    parser.add_argument("--seeds", default="0",
                        help="comma-separated training seeds of the methods that train "
                        "(neural3d): one result per seed and building (seed k > 0 in "
                        "<scene>__neural3d__train__seed<k>.json); the tables average a "
                        "building's seeds, then bootstrap over buildings, and report the "
                        "seed-to-seed spread (default: 0)")
    parser.add_argument("--device", default="cpu",
                        help="torch device for neural3d: cpu or cuda (default: cpu)")
    parser.add_argument("--degrade", metavar="NAME[:SEVERITY],...",
                        help="compare on degraded inputs (truth unchanged): "
                        f"{', '.join(DEGRADATIONS)}; see dataset/degrade/spec.py. Degraded "
                        "scenes are cached in <data>-degraded/, results go to "
                        "<results>/degraded/, outputs to <out>-<key>")
    parser.add_argument("--degrade-seed", type=int, default=0,
                        help="seed of the degradations (default: 0)")
    parser.add_argument("--robustness", action="store_true",
                        help="run the robustness study (mask noise, occluders, pose and depth "
                        "noise at three severities each; results in <results>/robustness, "
                        "table and plot in <out>/robustness)")
    parser.add_argument("--robustness-neural3d", choices=("all", "max"), default="max",
                        help="robustness study: neural3d at every severity or only at the "
                        "highest of each degradation (default: max)")
    parser.add_argument("--no-run", action="store_true",
                        help="only read existing result files; never run a method (results "
                        "made by other code or settings are marked stale)")
    parser.add_argument("--reuse-stale", action="store_true",
                        help="keep stored results made by other code or settings instead of "
                        "recomputing them; the tables mark them 'stale'")
    parser.add_argument("--list-methods", action="store_true",
                        help="list the built-in methods and those installed through the "
                        "envelope_bench.methods entry point group, then exit")
    parser.add_argument("--explain", nargs=2, metavar=("SCENE", "METHOD"),
                        help="print the full provenance record of one scene's result(s) of one "
                        "method, and whether the current code would reuse it; runs nothing")
    add_executor_arguments(parser, "missing runs one after the other in this process",
                           "building, method and views")
    add_debug_flag(parser)
    return parser.parse_args(argv)


def parse_seeds(text: str) -> tuple[int, ...]:
    """``--seeds``: distinct non-negative integers, in the order given.

    Raises
    ------
    ValueError
        If an entry is not a non-negative integer or repeats.
    """
    try:
        seeds = tuple(int(s) for s in text.split(",") if s.strip())
    except ValueError:
        raise ValueError(f"--seeds must be comma-separated integers, got {text!r}") from None
    if not seeds or min(seeds) < 0 or len(set(seeds)) != len(seeds):
        raise ValueError(f"--seeds needs distinct non-negative integers, got {text!r}")
    return seeds


def neural3d_config(args: argparse.Namespace, default: DefaultBenchmark | None) -> Neural3dBudget:
    """neural3d's config from the ``--neural3d-*`` options and ``--device``; the built-in
    default run (``default``) fills the step budget, resolution and eval frames not given.

    Raises
    ------
    ValueError
        If a value is out of range (0 steps included: a given 0 is not 'not given').
    """
    resolution = _given_or(args.neural3d_resolution,
                           default.neural3d_resolution if default else None)
    steps = _given_or(args.neural3d_steps, default.neural3d_steps if default else None)
    return Neural3dBudget(
        preset=args.neural3d_preset, steps=steps, max_minutes=args.neural3d_max_minutes,
        threads=args.neural3d_threads, resolution=resolution,
        eval_frames=default.neural3d_eval_frames if default else None, device=args.device,
    )


def study_config(configs: Mapping[str, Any]) -> dict[str, Any]:
    """The configs of a robustness study: neural3d with the given step budget, else the
    built-in default's (:attr:`DefaultBenchmark.neural3d_steps`), one eval frame, and the
    default run's marching-cubes resolution unless one was given."""
    budget = configs["neural3d"]
    return {**configs, "neural3d": replace(
        budget, steps=budget.steps or DefaultBenchmark.neural3d_steps, eval_frames=1,
        resolution=budget.resolution or DefaultBenchmark.neural3d_resolution)}


def _given_or(given: int | None, fallback: int | None) -> int | None:
    """A CLI value when given (0 included, so that the budget refuses it), else the fallback."""
    return fallback if given is None else given
