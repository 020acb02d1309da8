"""``python -m metrics.compare``: run what is missing, then print and write Tables 2 and 3.

With no arguments it runs the built-in default (the ``tiny`` benchmark, made
into a cache folder on first use, every method on the default views ``ideal``, ``multi``
and ``train`` that it declares, each method's short-run settings, ``Method.short_run``).
With ``--data`` it compares on a benchmark or a user's scenes. Outputs (``--out``): the
tables as CSV, Markdown and LaTeX, per-building and per-facade CSVs, plots (PNG + PDF),
``provenance.json``, the estimated footprints, the pipeline images of one facade
(of the first method that writes them) and, for each method that keeps a mesh,
``<method>_runs.json`` pointing at its meshes: everything ``figures.make`` reads;
then ``report.html``, all of it in one offline page (:mod:`metrics.report.html_report`).
The comparison itself is :func:`metrics.comparison.compare`; this module is its command line.

Its modes are small functions: :func:`compare_once` (with ``--degrade``, on
degraded inputs), :func:`compare_on_masks` (``--masks predicted[:MODEL]``, on a
segmenter's masks beside the exact ones), :func:`robustness_study`
(``--robustness``) and :func:`explain_one` (``--explain``); ``main`` works out the folders once
(:func:`metrics.run.compare_args.compare_request`).
"""

from __future__ import annotations

import sys
import time
from collections.abc import Sequence
from pathlib import Path

from dataset.benchmark_cache import ensure_benchmark
from envelope.cli_errors import check_output_folder, exit_cli, run_cli
from envelope.executors.ray_tasks import RayConfig
from envelope.method import available_methods
from envelope.scenes.scene import find_scene_folders
from metrics.comparison import PROVENANCE_FILE, compare
from metrics.predicted_masks import compare_on_predicted_masks
from metrics.report.tables import to_text
from metrics.robustness import RobustnessStudy, robustness_table, run_study
from metrics.run.compare_args import CompareRequest, compare_request, parse_compare_args
from metrics.run.degraded import degraded_run, with_degradation
from metrics.run.executors import make_executor
from metrics.run.explain import explain, recorded_steps
from metrics.run.methods import list_methods, method_specs
from metrics.run.predicted_masks import masks_segmenter
from metrics.run.runner import Execute, MethodSpec, execute_local


def main(argv: Sequence[str] | None = None) -> int:
    methods = available_methods()
    args = parse_compare_args(argv, methods)
    if args.list_methods:
        print("\n".join(list_methods()))
        return 0
    argv_text = " ".join(sys.argv[1:] if argv is None else argv)

    def body() -> int:
        request = compare_request(args, methods)
        if args.explain:
            return explain_one(request, *args.explain)
        check_output_folder(request.results, "--results")
        check_output_folder(request.out, "--out")
        execute = make_executor(
            args.executor, RayConfig(address=args.ray_address, num_cpus=args.cpus),
            cpus=args.cpus)
        if args.robustness:
            return robustness_study(request, RobustnessStudy(
                seed=args.degrade_seed, heavy_levels=args.robustness_heavy), execute=execute)
        mode = compare_on_masks if request.masks is not None else compare_once
        return mode(
            request, f"python -m metrics.compare {argv_text}".strip(),
            allow_run=not args.no_run, reuse_stale=args.reuse_stale, execute=execute)

    return run_cli("metrics.compare", body, debug=args.debug, interrupted=(
        "interrupted: finished results are kept; run again to continue"))


def compare_once(request: CompareRequest, command: str, *, allow_run: bool, reuse_stale: bool,
                 execute: Execute) -> int:
    """The comparison (on degraded copies of the scenes with ``--degrade``); print its tables."""
    start = time.perf_counter()
    _prepare(request)
    data, results, out = request.data, request.results, request.out
    if request.degradation:
        run = degraded_run(data, results, out, request.degradation)
        data, results, out = run.data, run.results, run.out
    specs = _specs(request, results)
    if request.degradation:
        specs = with_degradation(specs, request.degradation)
    comparison = compare(data, specs, results, out, allow_run=allow_run,
                         reuse_stale=reuse_stale, command=command, execute=execute)
    print()
    for table in comparison.printed:
        print(to_text(table))
    print(f"wrote tables, plots and {PROVENANCE_FILE} to {out} "
          f"(results in {results}); {time.perf_counter() - start:.0f} s")
    return 0


def compare_on_masks(request: CompareRequest, command: str, *, allow_run: bool,
                     reuse_stale: bool, execute: Execute) -> int:
    """``--masks predicted[:MODEL]``: the comparison on the exact masks and on a segmenter's
    (:mod:`metrics.predicted_masks`); print the table of both side by side (scenes without
    truth: the predicted-mask estimates). The segmenter is loaded first: refused weights or
    plugins stop the run before anything is made."""
    start = time.perf_counter()
    assert request.masks is not None
    segmenter = masks_segmenter(request.masks)
    _prepare(request, comparisons=2, inputs="exact and predicted masks")
    tables, run = compare_on_predicted_masks(
        segmenter, request.data, request.results, request.out,
        lambda results: _specs(request, results), command=command, allow_run=allow_run,
        reuse_stale=reuse_stale, execute=execute)
    print()
    for table in tables:
        print(to_text(table))
    print(f"wrote the exact-mask outputs to {request.out}, the predicted-mask outputs"
          + "".join(f" and {t.name}" for t in tables) + f" to {run.out} (masks in {run.data}, "
          f"results in {run.results}); {time.perf_counter() - start:.0f} s")
    return 0


def robustness_study(request: CompareRequest, study: RobustnessStudy, *,
                     execute: Execute = execute_local) -> int:
    """``--robustness``: the clean comparison and each degraded one, their missing runs
    made with ``execute``; print the study's table."""
    _prepare(request, study.heavy_comparisons)
    out = request.out / "robustness"
    rows = run_study(request.data, request.results / "robustness", out,
                     lambda results: _specs(request, results), study, execute=execute)
    print(to_text(robustness_table(rows)))
    print(f"wrote robustness.csv/.md/.png to {out}")
    return 0


def explain_one(request: CompareRequest, scene: str, method: str) -> int:
    """``--explain SCENE METHOD``: print one scene's result records of one method."""
    scene_dir = next((d for d in find_scene_folders(request.data) if d.name == scene), None)
    if scene_dir is None:
        raise ValueError(f"no scene {scene!r} in {request.data}")
    for spec in method_specs((method,), request.views, request.results,
                             configs=request.configs, seeds=request.seeds):
        print(explain(scene_dir, spec, request.results))
    return 0


def _specs(request: CompareRequest, results: Path) -> list[MethodSpec]:
    """The specs of the request's methods, keeping their artefacts under ``results``."""
    return method_specs(request.methods, request.views, results, configs=request.configs,
                        seeds=request.seeds)


def _prepare(request: CompareRequest, comparisons: int = 1,
             inputs: str = "clean and degraded inputs") -> None:
    """For the built-in default run: say what it does (``comparisons`` on ``inputs``), then
    generate its benchmark if absent."""
    if request.default is None:
        return
    steps = {s.name: n for s in _specs(request, request.results)
             if (n := recorded_steps(s.config)) is not None}
    print(request.default.announce(request.methods, steps, comparisons, inputs), flush=True)
    ensure_benchmark(request.default)


if __name__ == "__main__":
    exit_cli(main())

