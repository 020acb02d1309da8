"""Time and peak memory of marching-cubes extractions at 256³ and 512³
(neural3d.extraction.meshing).

    python bench/meshing.py                      # analytic L-shaped building, 256 and 512
    python bench/meshing.py --resolutions 128 256 --run runs/x --device cuda   # a trained field

Each resolution runs in a fresh process so that its peak resident memory
(``ru_maxrss``) is its own. The analytic building labels every vertex wall
except a window band 2 m < z < 4 m, roof included, so its WWR is
88 / 496 = 0.1774 (window band 44 m x 2 m over 352 m² of walls plus 144 m² of
roof and floor). The analytic SDF costs next to nothing, so its
figures are those of the grid, marching cubes and labelling themselves; a
trained field adds its own evaluation time.
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent


def _l_building_sdf(p: np.ndarray) -> np.ndarray:
    """L-shaped 10 x 12 x 8 m prism: [0, 10] x [0, 4] joined with [0, 4] x [0, 12]."""
    def box(lo, hi):
        lo, hi = np.asarray(lo, float), np.asarray(hi, float)
        q = np.abs(p - (lo + hi) / 2) - (hi - lo) / 2
        return np.linalg.norm(np.maximum(q, 0), axis=1) + np.minimum(q.max(axis=1), 0)

    return np.minimum(box([0, 0, 0], [10, 4, 8]), box([0, 0, 0], [4, 12, 8]))


def _band_labels(p: np.ndarray) -> np.ndarray:
    return np.where((p[:, 2] > 2) & (p[:, 2] < 4), 2, 1)


def run_one(resolution: int, run_dir: str | None, device: str) -> dict:
    """Extract once in this process; return times (s), sizes and peak RSS (MB)."""
    from neural3d.extraction.measure import measure_semantic_mesh
    from neural3d.extraction.meshing import extract_mesh, label_vertices

    rss_before_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    if run_dir is None:
        sdf, labels = _l_building_sdf, _band_labels
        lo, hi = np.array([-2.0, -1.0, -3.0]), np.array([12.0, 13.0, 11.0])  # a cube: n³ grid
    else:
        import torch

        from neural3d.extract import field_label_fn, field_sdf_fn
        from neural3d.field.trained import load_trained_field

        dev = torch.device(device)
        field = load_trained_field(Path(run_dir), device=dev)
        sdf, labels = field_sdf_fn(field, dev, 1 << 18), field_label_fn(field, dev, 1 << 18)
        lo, hi = field.box_min_m, field.box_max_m
    sdf_s = [0.0]

    def timed_sdf(points: np.ndarray) -> np.ndarray:
        t = time.perf_counter()
        out = sdf(points)
        sdf_s[0] += time.perf_counter() - t
        return out

    start = time.perf_counter()
    vertices, faces = extract_mesh(timed_sdf, lo, hi, resolution=resolution, progress=False)
    mesh_s = time.perf_counter() - start
    vertex_labels = label_vertices(vertices, labels)
    m = measure_semantic_mesh(vertices, faces, vertex_labels)
    total_s = time.perf_counter() - start
    return {
        "resolution": resolution,
        "mesh_s": round(mesh_s, 2),
        "sdf_s": round(sdf_s[0], 2),
        "label_measure_s": round(total_s - mesh_s, 2),
        "vertices": len(vertices),
        "faces": len(faces),
        "wwr": None if m.wwr is None else round(m.wwr, 4),
        "peak_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024),
        "rss_before_mb": round(rss_before_mb),
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--resolutions", type=int, nargs="+", default=[256, 512],
                        help="samples along the box's longest side (default 256 512)")
    parser.add_argument("--run", default=None, help="trained run folder (default: analytic SDF)")
    parser.add_argument("--device", default="cpu", choices=("cpu", "cuda"))
    parser.add_argument("--one", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.one:
        print(json.dumps(run_one(args.resolutions[0], args.run, args.device)))
        return 0
    print(f"{'res':>5} {'mesh s':>8} {'(in SDF) s':>11} {'label+measure s':>16} {'faces':>10} "
          f"{'peak RSS MB':>12} {'WWR':>7}")
    for res in args.resolutions:
        cmd = [sys.executable, __file__, "--one", "--resolutions", str(res),
               "--device", args.device] + (["--run", args.run] if args.run else [])
        out = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, check=False,
                             env={"PYTHONPATH": str(ROOT), **_env()})
        if out.returncode != 0:
            print(f"{res}: failed: {out.stderr.strip().splitlines()[-1:]}", file=sys.stderr)
            return 1
        r = json.loads(out.stdout.strip().splitlines()[-1])
        print(f"{res:>5} {r['mesh_s']:>8} {r['sdf_s']:>11} {r['label_measure_s']:>16} "
              f"{r['faces']:>10} "
              f"{r['peak_rss_mb']:>12} {r['wwr']!s:>7}")
    return 0


def _env() -> dict:
    import os

    return {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}


if __name__ == "__main__":
    sys.exit(main())
