"""What the 2D-S and 2D-SS command lines share: the benchmark, the results folder, the loop,
and the table of what was measured.

``--data`` is one scene folder (with ``transforms.json``) or a folder of scene
folders; without it, the built-in default benchmark of ``python -m metrics.compare``
(:class:`dataset.benchmark_cache.DefaultBenchmark`, generated into
``.cache/envelope-bench/tiny`` if missing). Results go to ``--out``, by default
``<data>-results`` (:func:`dataset.benchmark_cache.default_results_folder`), the folder
``python -m metrics.compare`` reads for the same ``--data``: ``--data /work/data/tiny``
writes to ``/work/data/tiny-results``.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path

from tqdm import tqdm

from dataset.benchmark_cache import DefaultBenchmark, default_results_folder, ensure_benchmark
from envelope.cli_errors import add_debug_flag, check_output_folder, one_line, run_cli
from envelope.method_input import MethodInput
from envelope.protocols import STREET_PROTOCOL, TRAIN_PROTOCOL, VIEW_PROTOCOLS
from envelope.results import MethodResult, write_result
from envelope.scenes.scene import find_scene_folders, read_method_input
from envelope.warnings_summary import summarise_warnings


def benchmark_folder(data: Path | None) -> Path:
    """``--data``, or without it the built-in default benchmark, generated if missing.

    Raises
    ------
    ValueError
        If the default benchmark cannot be generated.
    """
    if data is not None:
        return Path(data)
    default = DefaultBenchmark()
    made = "cached" if default.folder.is_dir() else "generating it now"
    print(f"no --data: the built-in '{default.preset}' benchmark in {default.folder} ({made})",
          file=sys.stderr)
    return ensure_benchmark(default)


def result_table(result: MethodResult) -> str:
    """What a result measured, for people: the building's WWR and areas, then one row per
    facade (WWR, window and facade areas in m2, views used; why, for a facade it missed)."""
    head = (f"{result.scene}  {result.method} {result.protocol}: building WWR "
            f"{_figure(result.wwr, 3)}, window {_figure(result.window_area_m2, 1)} m2 of "
            f"facade {_figure(result.facade_area_m2, 1)} m2")
    rows = [f"  {'facade':>6} {'WWR':>6} {'window m2':>10} {'facade m2':>10} {'views':>5}"]
    for f in result.facades:
        rows.append(f"  {f.id:>6} {_figure(f.wwr, 3):>6} {_figure(f.window_area_m2, 1):>10} "
                    f"{_figure(f.facade_area_m2, 1):>10} {f.views_used:>5}"
                    + (f"  missing: {f.reason}" if f.missing else ""))
    return "\n".join([head, *rows])


def _figure(value: float | None, digits: int) -> str:
    return "-" if value is None else f"{value:.{digits}f}"


def add_common_arguments(parser: argparse.ArgumentParser) -> None:
    """--views, --data, --out, --debug-images and --debug."""
    parser.add_argument("--views", required=True,
                        choices=(*VIEW_PROTOCOLS, TRAIN_PROTOCOL, STREET_PROTOCOL),
                        help="view protocol: 'ideal' (one perpendicular view per facade), "
                             "'multi' (several natural views per facade), both aimed at the "
                             "truth's facades, 'train' (the orbit views; a photos scene's "
                             "photos) or 'street' (a street capture, scenes made with --street); "
                             "on 'train' and 'street' the method finds its own facades")
    parser.add_argument("--data", type=Path, default=None,
                        help="a scene folder (with transforms.json) or a folder of scene folders "
                             "(default: the built-in tiny benchmark of metrics.compare, "
                             f"generated into {DefaultBenchmark().folder} if missing)")
    parser.add_argument("--out", type=Path, default=None,
                        help="folder for the result JSON files (default: <data>-results, where "
                             "python -m metrics.compare reads them)")
    parser.add_argument("--debug-images", type=Path, default=None, metavar="DIR",
                        help="also write debug PNGs <scene>__<protocol>__f<facade>__v<k>__<kind>"
                             ".png into DIR")
    add_debug_flag(parser)


def run_scenes(data: Path | None, out: Path | None,
               run_one: Callable[[MethodInput], MethodResult]) -> int:
    """Run one method on every scene of ``data`` (``None``: the default benchmark); write the
    result files, print what each measured (:func:`result_table`) and where it went; exit code.

    Warnings and per-scene failures go to stderr; a scene that fails does not
    stop the others.

    Raises
    ------
    ValueError
        If ``data`` holds no scene or no scene could be measured.
    """
    data = benchmark_folder(data)
    folders = find_scene_folders(data, with_images=True)
    out = check_output_folder(default_results_folder(data) if out is None else Path(out))
    written, failures = 0, []
    for folder in tqdm(folders, desc="scenes", unit="scene", disable=len(folders) < 2):
        try:
            result = run_one(read_method_input(folder))
        except ValueError as exc:
            failures.append(one_line(exc))
            if len(folders) > 1:
                print(f"error: {failures[-1]}", file=sys.stderr)
            continue
        for w in summarise_warnings(result.warnings):
            print(f"warning: {w}", file=sys.stderr)
        path = write_result(out, result)
        tqdm.write(f"{result_table(result)}\n  -> {path}")
        written += 1
    if written == 0:
        if len(folders) == 1:
            raise ValueError(failures[0])
        raise ValueError(f"nothing was measured in {data} ({len(failures)} scene(s) failed)")
    return 0


def main_guarded(prog: str, body: Callable[[], int], debug: bool = False) -> int:
    """Run a CLI body: a user's mistake becomes one line on stderr and exit 2
    (:func:`envelope.cli_errors.run_cli`)."""
    return run_cli(prog, body, debug=debug)
