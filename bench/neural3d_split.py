"""Window area by argmax labels or by class probabilities, on the same meshes of trained runs.

    python bench/neural3d_split.py --results DIR [--scenes NAME ...] [--resolution 256]
        [--threads 2] [--json FILE]

For every run a comparison kept (``DIR/neural3d_runs/<scene>/``, DIR being
``metrics.compare``'s ``--results``), the final field is meshed once
(``neural3d.extract.semantic_mesh_of_field``, marching cubes at
``--resolution``) and measured twice with the comparison's ``MeasureConfig``:
each triangle's facade area split among wall, window and door by its corners'
argmax labels, and by their class probabilities
(:mod:`neural3d.extraction.facade_split`, ``MeasureStages.probability_split``).
Prints, in Markdown, per building and per family, the window, facade and WWR
errors (APE %) of both against the scene's truth.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

# Run as a script, this file's folder is sys.path[0]: put the repository root there instead.
sys.path[0] = str(Path(__file__).resolve().parent.parent)

import torch  # noqa: E402

from bench.tables import markdown_table  # noqa: E402
from dataset.set_roles import refuse_report_only  # noqa: E402
from envelope.atomic import write_json_atomic  # noqa: E402
from envelope.results import code_version  # noqa: E402
from envelope.scenes.scene import read_scene  # noqa: E402
from metrics.score.errors import absolute_percentage_error  # noqa: E402
from neural3d.extract import semantic_mesh_of_field  # noqa: E402
from neural3d.extraction.extract_config import ExtractConfig  # noqa: E402
from neural3d.extraction.measure import measure_semantic_mesh  # noqa: E402
from neural3d.field.trained import load_trained_field  # noqa: E402
from neural3d.method import RUNS_FOLDER, trained_runs, trained_scene_dirs  # noqa: E402

SPLITS = ("labels", "probabilities")


def compare_splits(run_dir: Path, extract: ExtractConfig) -> dict:
    """One building: window / facade / WWR APE % with each split, on one mesh."""
    run = json.loads((run_dir / "run.json").read_text())
    truth = read_scene(run["scene_dir"], validate=False).building
    tic = time.perf_counter()
    field = load_trained_field(run_dir, device=torch.device("cpu"))
    mesh = semantic_mesh_of_field(field, extract, torch.device("cpu"))
    row: dict = {"scene": run_dir.name, "family": truth.type}
    for split in SPLITS:
        m = measure_semantic_mesh(
            mesh.vertices_m, mesh.faces, mesh.vertex_labels, config=extract.measure,
            vertex_probabilities=mesh.vertex_probabilities if split == "probabilities" else None)
        row[split] = {
            "window_ape": absolute_percentage_error(m.window_area_m2, truth.window_area_m2),
            "facade_ape": absolute_percentage_error(m.facade_area_m2, truth.facade_area_m2),
            "wwr_ape": absolute_percentage_error(m.wwr, truth.wwr),
            "window_bias_pct": 100.0 * (m.window_area_m2 / truth.window_area_m2 - 1.0),
        }
    row["measure_s"] = round(time.perf_counter() - tic, 1)
    print(f"  {row}", file=sys.stderr, flush=True)
    return row


def markdown(rows: list[dict]) -> str:
    """Per building and per family mean: window bias, window / facade / WWR APE of each split."""
    def cells(entries: list[dict]) -> list[str]:
        out = []
        for s in SPLITS:
            mean = {k: statistics.mean(e[s][k] for e in entries)
                    for k in ("window_bias_pct", "window_ape", "facade_ape", "wwr_ape")}
            out.append(f"{mean['window_bias_pct']:+.2f} / {mean['window_ape']:.2f} / "
                       f"{mean['facade_ape']:.2f} / {mean['wwr_ape']:.2f}")
        return out

    table = [[r["scene"], *cells([r])] for r in rows]
    for family in sorted({r["family"] for r in rows}, key=str):
        members = [r for r in rows if r["family"] == family]
        table.append([f"**{family} ({len(members)})**", *cells(members)])
    return markdown_table(
        "Window area by labels or by probabilities, per building and per family (mean)",
        ["building", *(f"{s}: window bias / window / facade / WWR %" for s in SPLITS)], table)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--results", type=Path, required=True,
                        help="a comparison's --results folder (holds neural3d_runs/)")
    parser.add_argument("--scenes", nargs="*", default=None, help="only these scene names")
    parser.add_argument("--resolution", type=int, default=ExtractConfig.resolution,
                        help="marching-cubes samples along the box's longest side")
    parser.add_argument("--threads", type=int, default=2,
                        help="torch threads (1 beside another torch job on 2 cores)")
    parser.add_argument("--json", type=Path, default=None, help="also write the figures here")
    args = parser.parse_args(argv)
    torch.set_num_threads(args.threads)
    runs = trained_runs(args.results, args.scenes)
    if not runs:
        parser.error(f"no trained runs in {args.results / RUNS_FOLDER}")
    try:
        refuse_report_only(trained_scene_dirs(runs), "compare the window-area rules")
    except ValueError as exc:
        parser.error(str(exc))
    extract = ExtractConfig(resolution=args.resolution)
    rows = [compare_splits(run, extract) for run in runs]
    print(f"code {code_version()}, marching cubes {args.resolution}, "
          f"{args.threads} thread(s)\n")
    print(markdown(rows))
    if args.json is not None:
        write_json_atomic(args.json, {"code_version": code_version(),
                                      "resolution": args.resolution, "buildings": rows})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
