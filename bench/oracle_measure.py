"""neural3d's measurement on a perfect field: each building's truth mesh plays the trained field.

    python -m bench.oracle_measure [--preset paper] [--buildings ID ...] [--resolution 256]
        [--without STAGE[,STAGE] ...] [--json FILE] [--threads 1]

Every building of a preset is rebuilt from its recipe
(:func:`dataset.presets.build_building`; nothing is rendered) and its truth mesh
becomes a perfect semantic field, :class:`OracleField`:

- **signed distance**: the distance to the nearest of the triangles under the
  :data:`CANDIDATE_FACES` surface samples nearest the point (random samples about a
  third of a voxel apart: exact but at a few points near edges, where it may be
  up to that spacing long), within :data:`BAND_VOXELS` voxels of the surface,
  clipped to that beyond (marching cubes reads only the cells the surface crosses); inside
  is the union of the mesh's closed bodies (ray parity per body: a chimney
  through a roof stays inside, as with the project's winding-number rule,
  :mod:`envelope.geometry.raycast`);
- **class probabilities**: one-hot of the label of the nearest truth face (that
  of the nearest surface sample). The ``probability_split`` stage is then the
  identity (a triangle's split by its corners' probabilities is its split by
  their labels): what it does for a blurred semantic head is measured on
  trained fields by ``bench/neural3d_stages.py``;
- **box**: the mesh's bounding box above the ground, widened on each side by
  ``TrainConfig.scene_box_margin`` of its longest side, as a trained field's
  visual-hull box is.

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
import hashlib
import sys
import time
from pathlib import Path

import numpy as np
import torch
import trimesh
from scipy.spatial import cKDTree
from tqdm import tqdm

from bench.neural3d_stages import ERROR_COLUMNS, Column, markdown, measure_sets, stage_sets
from dataset.presets import PRESETS, build_building, preset_recipes
from dataset.set_roles import PRESET_ROLES
from envelope.atomic import write_json_atomic
from envelope.classes import CLASS_NAMES, NUM_CLASSES
from envelope.mesh import LabelledMesh, triangle_areas_m2
from envelope.results import code_version
from neural3d.config import TrainConfig
from neural3d.extract import semantic_mesh_of_field
from neural3d.extraction.extract_config import STAGES, ExtractConfig

CANDIDATE_FACES = 8  # nearest surface samples whose triangles are tested exactly
SAMPLES_PER_VOXEL = 3  # surface samples per voxel length
BAND_VOXELS = 2  # the distance is exact this many voxels from the surface, clipped beyond
OFF_LOGIT = -1.0e4  # logit of every class but the nearest face's: softmax gives exactly 0
MEMO_ENTRIES = 32  # SDF answers kept: the footprint asks the same planes for every stage set
BIAS_KEYS = {"wwr": "wwr", "window": "window_area_m2", "facade": "facade_area_m2"}
COLUMNS = (Column("WWR bias %", "bias", "wwr", 2), Column("WWR APE %", "errors", "wwr_ape", 2),
           Column("window bias %", "bias", "window", 2),
           Column("window APE %", "errors", "window_ape", 2),
           Column("facade bias %", "bias", "facade", 2),
           Column("facade APE %", "errors", "facade_ape", 2), ERROR_COLUMNS[-1])


class OracleField:
    """A labelled truth mesh behind the interface of :class:`neural3d.field.trained.TrainedField`
    (world metres, CPU tensors): exact signed distance near the surface, one-hot classes of
    the nearest face, grey colour (module docstring).

    Parameters
    ----------
    mesh : the truth mesh, a union of closed bodies (each watertight)
    name : the building's id (``scene_name`` of its results)
    voxel_m : the marching-cubes voxel the field will be meshed at: it sets the surface
        samples' spacing (a third of it) and the exact band (:data:`BAND_VOXELS` of it)
    box_min_m, box_max_m : (3,) the box the field is meshed and outlined in

    Raises
    ------
    ValueError
        If a body of the mesh is not closed (ray parity needs closed bodies).
    """

    class_names = CLASS_NAMES
    device = torch.device("cpu")

    def __init__(self, mesh: LabelledMesh, name: str, *, voxel_m: float,
                 box_min_m: np.ndarray, box_max_m: np.ndarray):
        self.mesh = mesh
        self.scene_name = name
        self.box_min_m = np.asarray(box_min_m, dtype=np.float64)
        self.box_max_m = np.asarray(box_max_m, dtype=np.float64)
        self.band_m = BAND_VOXELS * voxel_m
        self.bodies = trimesh.Trimesh(mesh.vertices_m, mesh.faces).split(only_watertight=False,
                                                                          repair=False)
        if not all(body.is_watertight for body in self.bodies):
            raise ValueError(f"{name}: a body of the truth mesh is not closed; the oracle's "
                             "inside test (ray parity per body) needs closed bodies")
        tri = mesh.triangles_m
        spacing_m = voxel_m / SAMPLES_PER_VOXEL
        counts = np.maximum(1, np.ceil(triangle_areas_m2(tri) / spacing_m**2)).astype(int)
        self.sample_face = np.repeat(np.arange(len(tri)), counts)
        r = np.random.default_rng(0).random((len(self.sample_face), 2))
        r[r.sum(1) > 1] = 1 - r[r.sum(1) > 1]
        t = tri[self.sample_face]
        self.tree = cKDTree(t[:, 0] + r[:, :1] * (t[:, 1] - t[:, 0])
                            + r[:, 1:] * (t[:, 2] - t[:, 0]))
        self._memo: dict[bytes, np.ndarray] = {}

    def sdf(self, points_m: np.ndarray) -> np.ndarray:
        """(N, 3) world m -> (N,) signed distance in m, positive outside, clipped at the band."""
        key = hashlib.sha1(np.ascontiguousarray(points_m).tobytes()).digest()
        if key not in self._memo:
            if len(self._memo) >= MEMO_ENTRIES:
                self._memo.pop(next(iter(self._memo)))
            self._memo[key] = self._sdf(points_m)
        return self._memo[key]

    def _sdf(self, points_m: np.ndarray) -> np.ndarray:
        d, _ = self.tree.query(points_m, distance_upper_bound=self.band_m)
        d = np.minimum(d, self.band_m)
        near = np.flatnonzero(d < self.band_m)
        if len(near):
            _, idx = self.tree.query(points_m[near], k=CANDIDATE_FACES)
            faces = self.sample_face[idx].ravel()
            p = np.repeat(points_m[near], CANDIDATE_FACES, axis=0)
            closest = trimesh.triangles.closest_point(self.mesh.triangles_m[faces], p)
            d[near] = np.linalg.norm(closest - p, axis=1).reshape(-1, CANDIDATE_FACES).min(1)
        return np.where(self.contains(points_m), -d, d)

    def contains(self, points_m: np.ndarray) -> np.ndarray:
        """(N,) bool: inside one of the mesh's closed bodies (ray parity per body)."""
        inside = np.zeros(len(points_m), dtype=bool)
        for body in self.bodies:
            lo, hi = body.bounds
            box = np.flatnonzero(((points_m >= lo) & (points_m <= hi)).all(axis=1) & ~inside)
            if len(box):
                inside[box] = body.contains(points_m[box])
        return inside

    def labels(self, points_m: np.ndarray) -> np.ndarray:
        """(N, 3) world m -> (N,) class id of the nearest truth face."""
        _, idx = self.tree.query(points_m)
        return self.mesh.face_label[self.sample_face[idx]].astype(np.int64)

    def sdf_m(self, points_world_m: torch.Tensor, *, chunk_points: int = 0) -> torch.Tensor:
        """``TrainedField.sdf_m``: (N, 3) world points -> (N,) signed distance (m)."""
        return torch.from_numpy(self.sdf(points_world_m.double().numpy()))

    def semantic_logits(self, points_world_m: torch.Tensor, *,
                        chunk_points: int = 0) -> torch.Tensor:
        """``TrainedField.semantic_logits``: (N, C) logits whose softmax is exactly one-hot."""
        label = torch.from_numpy(self.labels(points_world_m.double().numpy()))
        logits = torch.full((len(label), NUM_CLASSES), OFF_LOGIT)
        logits[torch.arange(len(label)), label] = 0.0
        return logits

    def rgb(self, points_world_m: torch.Tensor, view_dirs_world: torch.Tensor, *,
            chunk_points: int = 0) -> torch.Tensor:
        """``TrainedField.rgb``: mid grey (the measurement reads no colour)."""
        return torch.full((len(points_world_m), 3), 0.5)


def scene_box_m(mesh: LabelledMesh, margin: float) -> tuple[np.ndarray, np.ndarray]:
    """A trained field's box for ``mesh``: its bounding box above z = 0 widened on each side
    by ``margin`` of its longest side (:func:`neural3d.training.scene_box.visual_hull_box_m`
    on a hull that is the building's box)."""
    lo, hi = mesh.vertices_m.min(axis=0), mesh.vertices_m.max(axis=0)
    lo[2] = max(lo[2], 0.0)
    extra = margin * float(np.max(hi - lo))
    return lo - extra, hi + extra


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
