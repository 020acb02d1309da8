"""``python -m figures.make``: the paper's tables and figures from what dataset and metrics wrote.

Inputs: the benchmark's scene folders (``--data``) and the output folder of
``python -m metrics.compare`` (``--results``). A figure whose input is missing
(no neural3d run yet, say) is skipped with a message; the others are made.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable, Sequence
from datetime import datetime, timezone
from pathlib import Path

from dataset.benchmark_cache import DefaultBenchmark
from envelope.atomic import write_json_atomic
from envelope.cli_errors import add_debug_flag, check_output_folder, exit_cli, run_cli
from envelope.results import code_version
from envelope.scenes.scene import find_scene_folders
from figures.dataset_table import read_truths, table1_dataset
from figures.footprints import footprint_pairs, plot_footprint_overlays
from figures.meshes import plot_reconstructed_meshes, reconstructed_meshes
from figures.pipeline import plot_2dss_pipeline
from figures.renders import plot_example_renders
from figures.style import MissingInput
from metrics.comparison import FOOTPRINTS_FOLDER, PIPELINE_FOLDER, PROVENANCE_FILE
from metrics.report.plots import plot_errors_by_family, plot_iou_per_building, plot_wwr_scatter
from metrics.report.report import PER_BUILDING_NAME, read_building_errors_csv
from metrics.report.tables import write_table
from metrics.score.aggregate import aggregate_by_family

FIGURES_PROVENANCE = "figures_provenance.json"


def make_figures(data: Path | None, results: Path, out: Path) -> dict[str, list[Path] | str]:
    """Make every figure it can; returns figure name -> written paths, or the reason it was skipped.

    Raises
    ------
    ValueError
        If ``results`` is not a folder.
    """
    if not results.is_dir():
        raise ValueError(
            f"comparison folder {results} does not exist; run `python -m metrics.compare` first"
        )
    if data is not None and not data.is_dir():
        raise ValueError(f"data folder {data} does not exist")
    try:
        truths = read_truths(find_scene_folders(data)) if data is not None else []
    except ValueError:
        truths = []  # a folder without scenes: the figures of the comparison are still made
    comment = (f"produced by `python -m figures.make` (envelope-bench {code_version()}) "
               f"from {data} and {results}")

    def rows():
        return read_building_errors_csv(results / f"{PER_BUILDING_NAME}.csv")

    makers: dict[str, Callable[[Path], list[Path]]] = {
        "table1_dataset": lambda stem: write_table(table1_dataset(truths), stem.parent, comment),
        "dataset_renders": lambda stem: plot_example_renders(truths, stem),
        "2dss_pipeline": lambda stem: plot_2dss_pipeline(results / PIPELINE_FOLDER, stem),
        "neural3d_meshes": lambda stem: plot_reconstructed_meshes(
            reconstructed_meshes(results, data), stem),
        "footprint_overlays": lambda stem: plot_footprint_overlays(
            footprint_pairs(truths, results / FOOTPRINTS_FOLDER), stem),
        "errors_by_family": lambda stem: plot_errors_by_family(aggregate_by_family(rows()), stem),
        "wwr_scatter": lambda stem: plot_wwr_scatter(rows(), stem),
        "iou_per_building": lambda stem: plot_iou_per_building(rows(), stem),
    }
    if data is None or not truths:
        reason = f"no scene with ground truth in {data}" if data else "no --data folder"
        skipped = {"table1_dataset", "dataset_renders", "footprint_overlays"}
    else:
        reason, skipped = "", set()
    made: dict[str, list[Path] | str] = {}
    for name, maker in makers.items():
        if name in skipped:
            made[name] = reason
            continue
        try:
            made[name] = maker(out / name)
        except (MissingInput, ValueError) as exc:
            made[name] = str(exc)
    write_json_atomic(out / FIGURES_PROVENANCE, {
        "produced_by": "python -m figures.make",
        "code_version": code_version(),
        "created_utc": datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "data": str(data.resolve()) if data else None,
        "results": str(results.resolve()),
        "figures": {k: [str(p) for p in v] if isinstance(v, list) else {"skipped": v}
                    for k, v in made.items()},
    })
    return made


def _default_data(results: Path) -> Path | None:
    """The data folder recorded in the comparison's provenance, if it still exists."""
    try:
        data = Path(json.loads((results / PROVENANCE_FILE).read_text())["data"])
    except (OSError, ValueError, KeyError):
        return None
    return data if data.is_dir() else None


def _parse_args(argv: Sequence[str] | None) -> argparse.Namespace:
    default = DefaultBenchmark().folder
    parser = argparse.ArgumentParser(
        prog="python -m figures.make",
        description=(
            "Make the paper's tables and figures (Table 1, example renders, the 2D-SS pipeline, "
            "reconstructed meshes, footprint overlays, error and IoU plots) as PNG + PDF from "
            "the benchmark and the output folder of `python -m metrics.compare`. Figures whose "
            "inputs are missing are skipped with a message."
        ),
    )
    parser.add_argument("--results", type=Path,
                        default=default.with_name(f"{default.name}-compare"),
                        help="output folder of metrics.compare (default: the built-in default's)")
    parser.add_argument("--data", type=Path,
                        help="benchmark folder (default: the one recorded in the comparison)")
    parser.add_argument("--out", type=Path, help="figures folder (default: <results>/figures)")
    add_debug_flag(parser)
    return parser.parse_args(argv)


def main(argv: Sequence[str] | None = None) -> int:
    args = _parse_args(argv)

    def body() -> int:
        data = args.data if args.data is not None else _default_data(args.results)
        out = args.out or args.results / "figures"
        check_output_folder(out)
        made = make_figures(data, args.results, out)
        for name, paths in made.items():
            if isinstance(paths, str):
                print(f"skipped {name}: {paths}", file=sys.stderr)
            else:
                print(f"made {name}: {', '.join(p.name for p in paths)}")
        if all(isinstance(v, str) for v in made.values()):
            raise ValueError(f"no figure could be made from {args.results}")
        print(f"figures in {out}")
        return 0

    return run_cli("figures.make", body, debug=args.debug)


if __name__ == "__main__":
    exit_cli(main())
