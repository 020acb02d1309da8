"""neural3d's measurement on a perfect field: each building's truth mesh plays the trained field.

    python -m bench.oracle_measure [--preset paper] [--buildings ID ...] [--resolution 256]
        [--without STAGE[,STAGE] ...] [--json FILE] [--threads 1]

Every building of a preset is rebuilt from its recipe
(:func:`dataset.presets.build_building`; nothing is rendered) and its truth mesh
becomes a perfect semantic field, :class:`neural3d.extraction.oracle.OracleField`
(exact signed distance near the surface, inside as the union of closed bodies, one-hot
classes of the nearest truth face), in the box a trained field would have
(:func:`neural3d.extraction.oracle.scene_box_m`: the mesh's bounding box above the ground,
widened on each side by ``TrainConfig.scene_box_margin`` of its longest side). The
``probability_split`` stage is then the identity (a triangle's split by its corners'
probabilities is its split by their labels): what it does for a blurred semantic head is
measured on trained fields by ``bench/neural3d_stages.py``.

neural3d's extraction then runs unchanged on it, as on a trained field:
:func:`neural3d.extract.semantic_mesh_of_field` (marching cubes at
``--resolution`` samples along the box's longest side, default
``ExtractConfig.resolution``, floaters dropped, labels) once per building, then
:func:`neural3d.extract.measure_mesh` (the measurement stages and the footprint)
with all stages on and with each stage of
:data:`neural3d.extraction.extract_config.STAGES` off (and the stages that need
it), or the sets given by ``--without``, through the stage bench's own code
(:func:`bench.neural3d_stages.measure_sets`). The errors are then those of the
measurement alone: voxel size, vertex labels, and each stage's assumptions met
on perfect geometry.

Prints, in Markdown, per family (mean) and per building and stage set: the
signed error (bias, ``100 * (estimate / truth - 1)``) and the absolute error
(APE) in % of the WWR, the window area and the gross facade area, and the
footprint IoU. ``--json FILE`` writes everything at full precision.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import torch
from tqdm import tqdm

from bench.neural3d_stages import ERROR_COLUMNS, Column, markdown, measure_sets, stage_sets
from dataset.presets import PRESETS, build_building, preset_recipes
from dataset.set_roles import PRESET_ROLES
from envelope.atomic import write_json_atomic
from envelope.results import code_version
from neural3d.config import TrainConfig
from neural3d.extract import semantic_mesh_of_field
from neural3d.extraction.extract_config import STAGES, ExtractConfig
from neural3d.extraction.oracle import OracleField, scene_box_m

BIAS_KEYS = {"wwr": "wwr", "window": "window_area_m2", "facade": "facade_area_m2"}
COLUMNS = (Column("WWR bias %", "bias", "wwr", 2), Column("WWR APE %", "errors", "wwr_ape", 2),
           Column("window bias %", "bias", "window", 2),
           Column("window APE %", "errors", "window_ape", 2),
           Column("facade bias %", "bias", "facade", 2),
           Column("facade APE %", "errors", "facade_ape", 2), ERROR_COLUMNS[-1])


def oracle_building(recipe, extract: ExtractConfig, sets: dict[str, tuple[str, ...]]) -> dict:
    """One building: its oracle mesh's size and, per stage set, the measured result, its
    errors (APE %, IoU) and its signed errors (bias %) against the truth."""
    building = build_building(recipe)
    truth = building.truth
    lo, hi = scene_box_m(building.mesh, TrainConfig().scene_box_margin)
    voxel_m = float(np.max(hi - lo)) / (extract.resolution - 1)
    field = OracleField(building.mesh, recipe.id, voxel_m=voxel_m, box_min_m=lo, box_max_m=hi)
    tic = time.perf_counter()
    mesh = semantic_mesh_of_field(field, extract, field.device)
    row = {"scene": recipe.id, "family": truth.type, "voxel_m": voxel_m,
           "mesh": {"vertices": len(mesh.vertices_m), "faces": len(mesh.faces)},
           "mesh_s": round(time.perf_counter() - tic, 1),
           "truth": {k: getattr(truth, key) for k, key in BIAS_KEYS.items()}}
    row["sets"] = measure_sets(field, mesh, truth, extract, sets, device=field.device)
    for entry in row["sets"].values():
        entry["bias"] = {k: signed_error_percent(entry["result"][key], row["truth"][k])
                         for k, key in BIAS_KEYS.items()}
    return row


def signed_error_percent(estimate: float | None, truth: float | None) -> float | None:
    """``100 * (estimate / truth - 1)``; None without both or with truth <= 0."""
    if estimate is None or truth is None or truth <= 0:
        return None
    return 100.0 * (estimate / truth - 1.0)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--preset", default="paper", choices=PRESETS,
                        help="the buildings (default paper)")
    parser.add_argument("--buildings", nargs="*", default=None, metavar="ID",
                        help="only these buildings of the preset")
    parser.add_argument("--resolution", type=int, default=ExtractConfig.resolution,
                        help="marching-cubes samples along the box's longest side (default "
                             f"{ExtractConfig.resolution}, neural3d's)")
    parser.add_argument("--without", action="append", default=None, metavar="STAGE[,STAGE]",
                        help="a stage set to measure with these stages off (repeat for more "
                             f"sets; default: each stage alone). Stages: {', '.join(STAGES)}")
    parser.add_argument("--threads", type=int, default=1, help="torch threads (default 1)")
    parser.add_argument("--json", type=Path, default=None, help="also write the figures here")
    args = parser.parse_args(argv)
    try:
        sets = stage_sets(args.without)
        extract = ExtractConfig(resolution=args.resolution)
    except ValueError as exc:
        parser.error(str(exc))
    if PRESET_ROLES.get(args.preset) == "report":
        parser.error(f"{args.preset} is a report-only preset; the oracle chooses stages: use a "
                     "tuning preset (paper, tiny) or the approval preset")
    recipes = [r for r in preset_recipes(args.preset)
               if args.buildings is None or r.id in args.buildings]
    unknown = sorted(set(args.buildings or ()) - {r.id for r in recipes})
    if unknown or not recipes:
        parser.error(f"no building(s) {unknown} in preset {args.preset}; its buildings: "
                     f"{', '.join(r.id for r in preset_recipes(args.preset))}")
    torch.set_num_threads(args.threads)
    buildings = [oracle_building(r, extract, sets)
                 for r in tqdm(recipes, desc="oracle", unit="building")]
    print(f"code {code_version()}, preset {args.preset}, marching cubes {args.resolution}, "
          "one-hot probabilities of the nearest truth face\n")
    print(markdown(buildings, COLUMNS))
    if args.json is not None:
        write_json_atomic(args.json, {
            "code_version": code_version(), "preset": args.preset,
            "resolution": args.resolution, "probabilities": "one-hot, nearest truth face",
            "buildings": buildings})
    return 0


if __name__ == "__main__":
    sys.exit(main())
