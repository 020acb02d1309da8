"""neural3d's facades on a perfect field, scored facade by facade under the one matching rule.

    python -m bench.oracle_facades [--preset paper] [--buildings ID ...] [--resolution 256]
        [--meshes DIR] [--json FILE] [--compare BEFORE.json]

Each building's truth mesh plays the trained field (``bench.oracle_measure.OracleField``),
is meshed at ``--resolution`` and measured with every stage on
(:func:`neural3d.extract.measure_mesh`); the result is scored as a comparison scores it:
building errors (:func:`metrics.score.errors.building_errors`) and one row per truth facade
(matched or missed) and per false positive (:func:`metrics.score.errors.facade_errors`,
which pairs the estimated facades with the truth's walls by
:func:`metrics.score.facade_match.match_facades`).

``--meshes DIR`` keeps each building's oracle mesh (``DIR/<id>.npz``) and reads it back on the
next run: the measurement can then be compared before and after an extraction change on the
same meshes, in a fraction of the time. ``--compare BEFORE.json`` prints the before/after table
of two runs' JSON files (per family: building WWR/window/facade APE, IoU, the matched
facades' mean WWR error in points, share within +-5 points, facade-area APE, and the
counts of missed facades and false positives).
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import asdict
from pathlib import Path

import numpy as np
import torch
from tqdm import tqdm

from dataset.presets import PRESETS, build_building, preset_recipes
from dataset.set_roles import PRESET_ROLES
from envelope.atomic import write_json_atomic
from envelope.results import code_version
from metrics.score.errors import building_errors, facade_errors
from neural3d.config import TrainConfig
from neural3d.extract import measure_mesh, semantic_mesh_of_field
from neural3d.extraction.extract_config import ExtractConfig
from neural3d.extraction.meshing import SemanticMesh
from neural3d.extraction.oracle import OracleField, scene_box_m

WITHIN_POINTS = 5.0  # a facade's WWR within this many points counts as close


def oracle_mesh(field: OracleField, extract: ExtractConfig, path: Path | None) -> SemanticMesh:
    """The oracle's semantic mesh, read from ``path`` when it is there, else made (and kept
    there when a path is given)."""
    if path is not None and path.exists():
        with np.load(path) as data:
            return SemanticMesh(**{k: data[k] for k in data.files})
    mesh = semantic_mesh_of_field(field, extract, field.device)
    if path is not None:
        path.parent.mkdir(parents=True, exist_ok=True)
        np.savez_compressed(path, **asdict(mesh))
    return mesh


def scored_building(recipe, extract: ExtractConfig, mesh_dir: Path | None) -> dict:
    """One building's building errors and per-facade rows on its oracle mesh."""
    building = build_building(recipe)
    truth = building.truth
    lo, hi = scene_box_m(building.mesh, TrainConfig().scene_box_margin)
    voxel_m = float(np.max(hi - lo)) / (extract.resolution - 1)
    field = OracleField(building.mesh, recipe.id, voxel_m=voxel_m, box_min_m=lo, box_max_m=hi)
    mesh = oracle_mesh(field, extract, None if mesh_dir is None else
                       mesh_dir / f"{recipe.id}-{extract.resolution}.npz")
    result = measure_mesh(field, mesh, extract, device=field.device)
    errors = building_errors(result, truth)
    rows = facade_errors(result, truth)
    print(f"  {recipe.id}: {len(result.facades)} facades, WWR APE {errors.wwr_ape}, "
          f"IoU {errors.footprint_iou}", file=sys.stderr, flush=True)
    return {"scene": recipe.id, "family": truth.type, "estimated_facades": len(result.facades),
            "building": {k: getattr(errors, k) for k in
                         ("wwr_ape", "window_ape", "facade_ape", "footprint_iou")},
            "facades": [{"id": r.facade_id, "kind": r.kind, "wwr_points": r.wwr_points,
                         "facade_ape": r.facade_ape, "facade_est_m2": r.facade_est_m2}
                        for r in rows]}


def summary(buildings: list[dict]) -> dict[str, float | int | None]:
    """Means over ``buildings`` (rows of :func:`scored_building`) and facade counts."""
    def mean(values):
        values = [v for v in values if v is not None]
        return float(np.mean(values)) if values else None
    facades = [f for b in buildings for f in b["facades"]]
    matched = [f for f in facades if f["kind"] == "matched"]
    points = [f["wwr_points"] for f in matched if f["wwr_points"] is not None]
    return {
        "buildings": len(buildings),
        "WWR APE %": mean(b["building"]["wwr_ape"] for b in buildings),
        "window APE %": mean(b["building"]["window_ape"] for b in buildings),
        "facade APE %": mean(b["building"]["facade_ape"] for b in buildings),
        "IoU": mean(b["building"]["footprint_iou"] for b in buildings),
        "truth facades": sum(f["kind"] != "false_positive" for f in facades),
        "missed": sum(f["kind"] == "missed" for f in facades),
        "false positives": sum(f["kind"] == "false_positive" for f in facades),
        "facade WWR error pt": mean(points),
        "within 5 pt %": 100.0 * np.mean([p <= WITHIN_POINTS for p in points]) if points
        else None,
        "facade area APE %": mean(f["facade_ape"] for f in matched),
    }


def compare_table(before: dict, after: dict) -> str:
    """Markdown: per family and overall, each summary figure before -> after."""
    def by_family(run):
        out: dict[str, list[dict]] = {}
        for b in run["buildings"]:
            out.setdefault(b["family"], []).append(b)
        out["all"] = run["buildings"]
        return out
    fam_before, fam_after = by_family(before), by_family(after)
    keys = list(summary(before["buildings"]))
    lines = ["| family | " + " | ".join(keys) + " |", "|---" * (len(keys) + 1) + "|"]
    for family in fam_after:
        s0, s1 = summary(fam_before.get(family, [])), summary(fam_after[family])
        cells = [_cell(s0[k], s1[k]) for k in keys]
        lines.append(f"| {family} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def building_table(before: dict, after: dict) -> str:
    """Markdown: every building whose facade count or figures changed, before -> after."""
    old = {b["scene"]: b for b in before["buildings"]}
    keys = list(summary([]))[1:]
    lines = ["| building | " + " | ".join(keys) + " |", "|---" * (len(keys) + 1) + "|"]
    for b in after["buildings"]:
        s0, s1 = summary([old[b["scene"]]]), summary([b])
        if s0 != s1:
            lines.append(f"| {b['scene']} | " + " | ".join(_cell(s0[k], s1[k]) for k in keys)
                         + " |")
    return "\n".join(lines)


def _cell(a, b) -> str:
    def fmt(v):
        return "-" if v is None else (str(v) if isinstance(v, int) else f"{v:.3f}")
    return fmt(b) if a == b else f"{fmt(a)} → {fmt(b)}"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--preset", default="paper", choices=PRESETS)
    parser.add_argument("--buildings", nargs="*", default=None, metavar="ID")
    parser.add_argument("--resolution", type=int, default=ExtractConfig.resolution)
    parser.add_argument("--meshes", type=Path, default=None, metavar="DIR",
                        help="keep and reuse the oracle meshes here")
    parser.add_argument("--json", type=Path, default=None, help="write the figures here")
    parser.add_argument("--compare", type=Path, default=None, metavar="BEFORE.json",
                        help="print before -> after against this earlier run's JSON")
    args = parser.parse_args(argv)
    if PRESET_ROLES.get(args.preset) == "report":
        parser.error(f"{args.preset} is a report-only preset: use a tuning preset")
    recipes = [r for r in preset_recipes(args.preset)
               if args.buildings is None or r.id in args.buildings]
    if not recipes:
        parser.error(f"no such building(s) in preset {args.preset}")
    torch.set_num_threads(1)
    extract = ExtractConfig(resolution=args.resolution)
    run = {"code_version": code_version(), "preset": args.preset,
           "resolution": args.resolution,
           "buildings": [scored_building(r, extract, args.meshes)
                         for r in tqdm(recipes, desc="oracle", unit="building")]}
    if args.json is not None:
        write_json_atomic(args.json, run)
    print(f"code {run['code_version']}, preset {args.preset}, marching cubes "
          f"{args.resolution}, oracle field\n")
    if args.compare is not None:
        before = json.loads(args.compare.read_text())
        print(f"before: code {before['code_version']}\n")
        print(compare_table(before, run) + "\n\n" + building_table(before, run))
    else:
        print(compare_table(run, run))
    return 0


if __name__ == "__main__":
    sys.exit(main())
