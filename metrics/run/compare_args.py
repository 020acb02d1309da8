"""The command line of ``python -m metrics.compare``: its options, their help and defaults,
and what one call compares (:class:`CompareRequest`, its folders worked out once).

The methods' own options (``--device``, ...) and ``--set`` come from the methods
(:mod:`metrics.run.method_args`).
"""

from __future__ import annotations

import argparse
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from dataset.benchmark_cache import DEFAULT_CACHE, DefaultBenchmark, default_results_folder
from dataset.degrade.spec import DEGRADATIONS, DegradeSpec, parse_specs
from envelope.cli_errors import add_debug_flag
from envelope.executors.ray_tasks import add_executor_arguments
from envelope.method import Method
from envelope.protocols import DEFAULT_PROTOCOLS
from metrics.run.method_args import add_method_options, method_configs
from metrics.run.methods import METHODS
from metrics.run.predicted_masks import MasksRequest, parse_masks


@dataclass(frozen=True)
class CompareRequest:
    """What one call compares: ``data`` (resolved), ``results`` and ``out`` (their
    defaults worked out), the methods and views, each method's config, the built-in
    default run (``default``, when ``--data`` is not given), the ``--degrade`` specs and the
    segmenter of ``--masks`` (``masks``; ``None``: the exact masks)."""

    data: Path
    results: Path
    out: Path
    methods: tuple[str, ...]
    views: tuple[str, ...]
    configs: dict[str, Any]
    default: DefaultBenchmark | None
    degradation: tuple[DegradeSpec, ...]
    seeds: tuple[int, ...] = (0,)
    masks: MasksRequest | None = None


def parse_compare_args(argv: Sequence[str] | None,
                       methods: Mapping[str, Method]) -> argparse.Namespace:
    """The options of ``python -m metrics.compare`` (``--help`` explains each), with the
    options that ``methods`` declare."""
    parser = argparse.ArgumentParser(
        prog="python -m metrics.compare",
        description=(
            "Compare WWR / window / facade-area and footprint estimates of the methods "
            "(--list-methods) against ground truth, running only the results that are missing. "
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
    parser.add_argument("--views", default=",".join(DEFAULT_PROTOCOLS),
                        help="comma-separated view protocols; each method runs on those it "
                        "declares (--list-methods): ideal, multi (views aimed at the truth's "
                        "facades, as in the paper: the 2D methods), train (the orbit views, "
                        "a photos scene's photos: every built-in method), street (a street "
                        "capture placed without the truth, scenes made with --street: every "
                        "built-in method); on train and street every method finds its own "
                        f"facades (default: {','.join(DEFAULT_PROTOCOLS)}; a photos scene: "
                        "train)")
    parser.add_argument("--results", type=Path,
                        help="folder of result JSONs to read and fill (default: <data>-results)")
    parser.add_argument("--out", type=Path,
                        help="folder for tables, plots, provenance (default: <data>-compare)")
    parser.add_argument("--seeds", default="0",
                        help="comma-separated training seeds of the methods whose config has a "
                        "seed field (a trained method's): one result per seed and building "
                        "(seed k > 0 in <scene>__<method>__<protocol>__seed<k>.json); the "
                        "tables average a building's seeds, then bootstrap over buildings, "
                        "and report the seed-to-seed spread (default: 0)")
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument("--degrade", metavar="NAME[:SEVERITY],...",
                        help="compare on degraded inputs (truth unchanged): "
                        f"{', '.join(DEGRADATIONS)}; see dataset/degrade/spec.py. Degraded "
                        "scenes are cached in <data>-degraded/, results go to "
                        "<results>/degraded/, outputs to <out>-<key>")
    parser.add_argument("--degrade-seed", type=int, default=0,
                        help="seed of the degradations (default: 0)")
    mode.add_argument(
        "--masks", metavar="predicted[:MODEL]",
        help="compare on a segmenter's masks instead of the exact ones (truth unchanged): "
        "'predicted' uses the default committed weights, 'predicted:NAME' other committed "
        "weights by name (segment.weights.BUILT_IN_WEIGHTS), 'predicted:FILE.pt' other "
        "weights, 'predicted:NAME' also an installed plugin (entry point group "
        "envelope_bench.segmenters). The exact-mask comparison runs too; "
        "masks are cached in <data>-masks/, results go to <results>/masks/, outputs to "
        "<out>-masks-<key> with the table exact_vs_predicted. See docs/segment.md")
    parser.add_argument("--masks-threads", type=int, default=2,
                        help="--masks: torch threads of the segmenter (default: 2)")
    mode.add_argument("--robustness", action="store_true",
                        help="run the robustness study (mask noise, occluders, pose and depth "
                        "noise at three severities each; results in <results>/robustness, "
                        "table and plot in <out>/robustness)")
    parser.add_argument("--robustness-heavy", choices=("all", "max"), default="max",
                        help="robustness study: the heavy methods (those that train) at every "
                        "severity or only at the highest of each degradation (default: max)")
    parser.add_argument("--no-run", action="store_true",
                        help="only read existing result files; never run a method (results "
                        "made by other code or settings are marked stale)")
    parser.add_argument("--reuse-stale", action="store_true",
                        help="keep stored results made by other code or settings instead of "
                        "recomputing them; the tables mark them 'stale'")
    parser.add_argument("--list-methods", action="store_true",
                        help="list the built-in methods and those installed through the "
                        "envelope_bench.methods entry point group, then exit")
    mode.add_argument("--explain", nargs=2, metavar=("SCENE", "METHOD"),
                        help="print the full provenance record of one scene's result(s) of one "
                        "method, and whether the current code would reuse it; runs nothing")
    add_executor_arguments(parser, "missing runs one after the other in this process",
                           "building, method and views", processes_help=(
                               "the light methods here, then each heavy run (a training) in "
                               "a process of its own, as many at once as fit in --cpus and the "
                               "GPU; what a run reserves is its method's: a training the cores "
                               "of its threads, or its share of the GPU with --device cuda"))
    add_debug_flag(parser)
    add_method_options(parser, methods)
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



def compare_request(args: argparse.Namespace, methods: Mapping[str, Method]) -> CompareRequest:
    """What ``args`` asks to compare. Without ``--data``, the built-in default's folder
    (not generated here); ``--results`` and ``--out`` default to ``<data>-results`` and
    ``<data>-compare``; with ``--explain SCENE METHOD`` the one method is METHOD. The
    methods' configs take their short-run values in the built-in default run and the
    robustness study, and are checked for running here unless nothing runs in this
    machine (``--no-run``, ``--explain``, a Ray executor: its GPUs are on its nodes).

    Raises
    ------
    ValueError
        If a method option, ``--set``, ``--degrade`` or ``--masks`` is refused.
    """
    default = DefaultBenchmark() if args.data is None else None
    data = (default.folder if default is not None else args.data).resolve()
    names = (args.explain[1],) if args.explain else _listed(args.methods)
    runs_here = args.executor != "ray" and not (args.no_run or args.explain)
    configs = method_configs(args, methods, names, runs_here=runs_here,
                             short_run=default is not None or args.robustness)
    return CompareRequest(
        data=data, results=args.results or default_results_folder(data),
        out=args.out or data.with_name(f"{data.name}-compare"), methods=names,
        views=_listed(args.views), configs=configs, default=default,
        degradation=parse_specs(args.degrade, seed=args.degrade_seed) if args.degrade else (),
        seeds=parse_seeds(args.seeds),
        masks=parse_masks(args.masks, args.masks_threads) if args.masks else None)


def _listed(text: str) -> tuple[str, ...]:
    """The items of a comma-separated option."""
    return tuple(item.strip() for item in text.split(",") if item.strip())


