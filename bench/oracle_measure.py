"""How well does the mesh measurement recover the truth when the field is perfect?

    python -m bench.oracle_measure [--preset tiny] [--resolutions 128 256] [--facades]

For each building of a preset the ground-truth mesh itself plays the trained
field: the SDF is its exact signed distance (sign from ray-parity inside tests,
magnitude from the nearest of the triangles near the query) and the label of
a point is that of the nearest truth face. The pipeline of
``neural3d.extract`` then runs unchanged (mesh, vertex labels, areas, facade
grouping, footprint), so the errors printed are those of the measurement step
alone: voxel size, vertex-fraction areas, and the window reveals that the
paper's count (``all``: every triangle, no plane projection) counts as window
area while the truth does not (``projected``: every stage on).
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np
from scipy.spatial import cKDTree
from shapely.geometry import shape

from dataset.core.mesh import LabelledMesh, triangle_areas_m2
from dataset.presets import build_building, preset_recipes
from metrics.facade_match import match_facades
from neural3d.extract import facade_estimates
from neural3d.extraction.footprint import footprint_from_sdf
from neural3d.extraction.measure import measure_semantic_mesh
from neural3d.extraction.measure_config import MeasureConfig, MeasureStages
from neural3d.extraction.meshing import extract_mesh, label_vertices

CANDIDATE_FACES = 8  # nearest surface samples whose triangles are tested exactly


class OracleField:
    """Exact SDF and labels of a closed labelled mesh, as NumPy callables."""

    def __init__(self, mesh: LabelledMesh, spacing_m: float):
        import trimesh

        self.mesh = mesh
        self.trimesh = trimesh.Trimesh(mesh.vertices_m, mesh.faces, process=False)
        tri = mesh.triangles_m
        counts = np.maximum(1, np.ceil(triangle_areas_m2(tri) / spacing_m**2)).astype(int)
        self.sample_face = np.repeat(np.arange(len(tri)), counts)
        rng = np.random.default_rng(0)
        r = rng.random((len(self.sample_face), 2))
        r[r.sum(1) > 1] = 1 - r[r.sum(1) > 1]
        t = tri[self.sample_face]
        samples = t[:, 0] + r[:, :1] * (t[:, 1] - t[:, 0]) + r[:, 1:] * (t[:, 2] - t[:, 0])
        self.tree = cKDTree(samples)
        # exact within the band (2 voxels at spacing = voxel / 3); beyond it the SDF is
        # clipped (truncated SDF): marching cubes reads only cells the surface crosses
        self.band_m = 6 * spacing_m

    def sdf(self, points_m: np.ndarray) -> np.ndarray:
        import trimesh

        d, _ = self.tree.query(points_m, distance_upper_bound=self.band_m)
        d = np.minimum(d, self.band_m)
        near = np.flatnonzero(d < self.band_m)
        if len(near):
            _, idx = self.tree.query(points_m[near], k=CANDIDATE_FACES)
            faces = self.sample_face[idx].ravel()
            p = np.repeat(points_m[near], CANDIDATE_FACES, axis=0)
            closest = trimesh.triangles.closest_point(self.mesh.triangles_m[faces], p)
            d[near] = np.linalg.norm(closest - p, axis=1).reshape(-1, CANDIDATE_FACES).min(1)
        inside = self.trimesh.contains(points_m)
        return np.where(inside, -d, d)

    def labels(self, points_m: np.ndarray) -> np.ndarray:
        _, idx = self.tree.query(points_m)
        return self.mesh.face_label[self.sample_face[idx]].astype(np.int64)


def _print_facades(m, building) -> None:
    match = match_facades(facade_estimates(m), building.truth)
    for t, e in zip(building.truth.facades, match.facades):
        est = e.reason if e.missing else (
            f"WWR {e.wwr:.3f} ({e.wwr - t.wwr:+.3f}), {e.facade_area_m2:.1f} m², "
            f"{e.width_m:.2f} x {e.height_m:.2f} m")
        print(f"    facade {t.id}: truth WWR {t.wwr:.3f}, {t.facade_area_m2:.1f} m², "
              f"{t.width_m:.2f} x {t.height_m:.2f} m | {est}")
    for _, reason in match.left_out:
        print(f"    {reason}")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--preset", default="tiny")
    parser.add_argument("--resolutions", type=int, nargs="+", default=[128, 256])
    parser.add_argument("--facades", action="store_true",
                        help="also print per-facade WWR (truth ids via metrics.facade_match)")
    args = parser.parse_args()
    print(f"{'building':18} {'res':>4} {'voxel m':>7} {'count':>8} {'WWR':>7} {'truth':>7} "
          f"{'err':>7} {'window %':>9} {'facade %':>9} {'IoU':>6} {'s':>5}")
    for recipe in preset_recipes(args.preset):
        building = build_building(recipe)
        truth = building.truth
        lo = building.mesh.vertices_m.min(0) - 1.0
        hi = building.mesh.vertices_m.max(0) + 1.0
        lo[2] = 0.0  # like a scene box cut at the ground: the base stays open
        for res in args.resolutions:
            start = time.perf_counter()
            voxel = float(np.max(hi - lo)) / (res - 1)
            oracle = OracleField(building.mesh, spacing_m=voxel / 3)
            v, f = extract_mesh(oracle.sdf, lo, hi, resolution=res)
            labels = label_vertices(v, oracle.labels)
            poly = footprint_from_sdf(oracle.sdf, lo, hi, heights_m=(0.5,), cell_m=voxel / 2,
                                      min_area_m2=1.0)
            truth_fp = shape(truth.footprint)
            iou = poly.intersection(truth_fp).area / poly.union(truth_fp).area
            seconds = time.perf_counter() - start
            for count, stages in (("projected", MeasureStages()),
                                  ("all", MeasureStages().without("plane_projection"))):
                m = measure_semantic_mesh(v, f, labels, config=MeasureConfig(stages=stages))
                print(f"{recipe.id:18} {res:>4} {voxel:>7.3f} {count:>8} {m.wwr:>7.4f} "
                      f"{truth.wwr:>7.4f} {m.wwr - truth.wwr:>+7.4f} "
                      f"{100 * (m.window_area_m2 / truth.window_area_m2 - 1):>+9.1f} "
                      f"{100 * (m.facade_area_m2 / truth.facade_area_m2 - 1):>+9.1f} "
                      f"{iou:>6.4f} {seconds:>5.0f}", flush=True)
                if args.facades:
                    _print_facades(m, building)
    return 0


if __name__ == "__main__":
    sys.exit(main())
