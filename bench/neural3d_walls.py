"""neural3d's footprint with and without straight walls, over a grid of their two settings.

    python bench/neural3d_walls.py --results DIR [--scenes NAME ...] [--resolution 256]
        [--tolerances 0.05 0.1 ...] [--min-walls 0.5 1 ...] [--threads 2] [--json FILE]

For every run a comparison kept (``DIR/neural3d_runs/<scene>/``, DIR being
``metrics.compare``'s ``--results``), the final field's footprint is taken once
as the extraction takes it before its last stage
(:func:`neural3d.extraction.footprint.footprint_from_sdf` with
:class:`neural3d.extract.ExtractConfig` at ``--resolution``, whose grid spacing
is half its voxel), then straightened
(:func:`neural3d.extraction.straight_walls.straighten_footprint`) with every
pair of ``--tolerances`` x ``--min-walls``. Prints, in Markdown, the footprint
IoU against the truth (as a comparison computes it, from the GeoJSON) per
building (the contour as is, then each pair) and per family: the mean, the
lowest, and how many buildings each pair makes worse by more than 0.001. Only
the SDF on the footprint planes is queried: no mesh.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
from pathlib import Path

# Run as a script, this file's folder is sys.path[0]: put the repository root there instead.
if not __package__:
    sys.path[0] = str(Path(__file__).resolve().parent.parent)

import torch  # noqa: E402

from bench.tables import markdown_table  # noqa: E402
from dataset.set_roles import refuse_report_only  # noqa: E402
from envelope.atomic import write_json_atomic  # noqa: E402
from envelope.footprint import geojson_to_polygon, polygon_to_geojson  # noqa: E402
from envelope.results import code_version  # noqa: E402
from envelope.scenes.scene import read_scene  # noqa: E402
from metrics.score.errors import footprint_iou  # noqa: E402
from neural3d.extract import field_sdf_fn  # noqa: E402
from neural3d.extraction.extract_config import (  # noqa: E402
    ExtractConfig,
    footprint_cell_m,
    footprint_heights_m,
)
from neural3d.extraction.footprint import footprint_from_sdf  # noqa: E402
from neural3d.extraction.straight_walls import straighten_footprint  # noqa: E402
from neural3d.field.trained import load_trained_field  # noqa: E402
from neural3d.method import RUNS_FOLDER, trained_runs, trained_scene_dirs  # noqa: E402

CONTOUR = "contour"  # the column of the footprint as the contour gives it
WORSE_BY = 0.001  # a pair "makes a building worse" when its IoU falls by more than this


def pair_label(tolerance_m: float, min_wall_m: float) -> str:
    return f"{tolerance_m:g}/{min_wall_m:g}"


def building_ious(run_dir: Path, extract: ExtractConfig,
                  pairs: list[tuple[float, float]]) -> dict:
    """One building's family and IoU per column: the contour, then each (tolerance, wall)."""
    run = json.loads((run_dir / "run.json").read_text())
    truth = read_scene(run["scene_dir"], validate=False).building
    if truth is None or truth.footprint is None:
        raise ValueError(f"{run['scene_dir']} has no truth footprint to compare with")
    device = torch.device("cpu")
    field = load_trained_field(run_dir, device=device)
    contour = footprint_from_sdf(
        field_sdf_fn(field, device, extract.chunk_points), field.box_min_m, field.box_max_m,
        heights_m=footprint_heights_m(field.box_max_m, extract),
        cell_m=footprint_cell_m(field.box_min_m, field.box_max_m, extract),
        min_area_m2=extract.footprint_min_area_m2, roofed_hole_fill=extract.roofed_hole_fill)
    true_polygon = geojson_to_polygon(truth.footprint)
    ious = {CONTOUR: footprint_iou(_as_written(contour), true_polygon)}
    for tolerance_m, min_wall_m in pairs:
        straight = straighten_footprint(contour, tolerance_m=tolerance_m, min_wall_m=min_wall_m)
        ious[pair_label(tolerance_m, min_wall_m)] = footprint_iou(_as_written(straight),
                                                                 true_polygon)
    print(f"  {run_dir.name}: contour {ious[CONTOUR]:.4f}", file=sys.stderr, flush=True)
    return {"scene": run_dir.name, "family": truth.type, "iou": ious}


def _as_written(polygon):
    """The footprint as a comparison reads it back from the result's GeoJSON."""
    return geojson_to_polygon(polygon_to_geojson(polygon))


def markdown(buildings: list[dict]) -> str:
    """Per building the IoU of each column, then per family (and all) mean, lowest and
    the count of buildings each column makes worse than the contour by > WORSE_BY."""
    columns = list(buildings[0]["iou"])
    per_building = [[b["scene"], b["family"], *(f"{b['iou'][c]:.4f}" for c in columns)]
                    for b in buildings]
    per_family = []
    for family in sorted({b["family"] for b in buildings}) + ["all"]:
        group = [b for b in buildings if family in ("all", b["family"])]
        mean = [statistics.fmean(b["iou"][c] for b in group) for c in columns]
        low = [min(b["iou"][c] for b in group) for c in columns]
        worse = [sum(b["iou"][c] < b["iou"][CONTOUR] - WORSE_BY for b in group)
                 for c in columns]
        per_family += [[f"{family} ({len(group)})", "mean", *(f"{v:.4f}" for v in mean)],
                       ["", "lowest", *(f"{v:.4f}" for v in low)],
                       ["", f"worse by > {WORSE_BY}", *worse]]
    return "\n\n".join([
        markdown_table("Footprint IoU per building", ["building", "family", *columns],
                       per_building),
        markdown_table("Footprint IoU per family", ["family (buildings)", "figure", *columns],
                       per_family)])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--results", type=Path, required=True,
                        help="a comparison's --results folder (holds neural3d_runs/)")
    parser.add_argument("--scenes", nargs="*", default=None, help="only these scene names")
    parser.add_argument("--resolution", type=int, default=ExtractConfig.resolution,
                        help="the extraction's marching-cubes resolution, which sets the "
                             f"footprint grid (default {ExtractConfig.resolution}; the "
                             "comparison's own to match its footprints)")
    parser.add_argument("--tolerances", type=float, nargs="+",
                        default=[ExtractConfig.footprint_wall_tolerance_m],
                        help="straight-wall tolerances to try, m (default: the extraction's)")
    parser.add_argument("--min-walls", type=float, nargs="+",
                        default=[ExtractConfig.footprint_min_wall_m],
                        help="shortest straight walls to try, m (default: the extraction's)")
    parser.add_argument("--threads", type=int, default=2,
                        help="torch threads (1 beside another torch job on 2 cores)")
    parser.add_argument("--json", type=Path, default=None, help="also write the figures here")
    args = parser.parse_args(argv)
    runs = trained_runs(args.results, args.scenes)
    if not runs:
        parser.error(f"no trained runs in {args.results / RUNS_FOLDER}")
    try:
        refuse_report_only(trained_scene_dirs(runs), "choose the straight-walls settings")
    except ValueError as exc:
        parser.error(str(exc))
    if min(args.tolerances + args.min_walls) <= 0:
        parser.error("--tolerances and --min-walls must be > 0")
    torch.set_num_threads(args.threads)
    extract = ExtractConfig(resolution=args.resolution)
    pairs = [(t, w) for t in args.tolerances for w in args.min_walls]
    try:
        buildings = [building_ious(run, extract, pairs) for run in runs]
    except ValueError as exc:  # no truth, or no footprint in a field
        parser.error(str(exc))
    print(f"code {code_version()}, footprint grid of marching cubes {args.resolution}, "
          f"columns tolerance/shortest wall in m\n")
    print(markdown(buildings))
    if args.json is not None:
        write_json_atomic(args.json, {"code_version": code_version(),
                                      "resolution": args.resolution, "buildings": buildings})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
