"""How much of the lod3 buildings' covered facades the street capture sees; prints Markdown.

    python bench/street_views.py [ID ...] [--no-context] [--out FILE]

For each shipped building (default: all 49): its street stations and frames with the
``--street`` defaults (:mod:`dataset.rendering.street_views`, neighbours as occluders unless
``--no-context``), and, **measured with the truth** (placement never reads it), which share
of each covered facade the frames see: 500 points per facade spread over its mesh faces by
area; a point is seen when some frame has it in the image, in front of the camera, with
nothing (building or neighbour) in between (1 cm slack). A facade counts as seen when at
least half its points are; the building's coverage is the seen share weighted by the
truth's facade areas.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from dataset.importers.citygml.preset import build_lod3_building, lod3_entries  # noqa: E402
from dataset.rendering.street_views import (  # noqa: E402
    StreetConfig,
    scene_caster,
    street_stations,
    street_views,
)
from envelope.camera import project_world_to_image  # noqa: E402

SAMPLES = 500
SEEN = 0.5


def facade_points_m(building, facade_id: int, rng: np.random.Generator) -> np.ndarray:
    """(SAMPLES, 3) points on the faces of ``facade_id``, spread by area."""
    mesh = building.mesh
    tri = mesh.triangles_m[mesh.face_facade == facade_id]
    areas = mesh.face_areas_m2()[mesh.face_facade == facade_id]
    pick = rng.choice(len(tri), size=SAMPLES, p=areas / areas.sum())
    a, b = rng.uniform(size=(2, SAMPLES))
    flip = a + b > 1
    a[flip], b[flip] = 1 - a[flip], 1 - b[flip]
    t = tri[pick]
    # 1 cm off the surface towards the outside, so the facade's own face does not stop a ray
    n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    return t[:, 0] + a[:, None] * (t[:, 1] - t[:, 0]) + b[:, None] * (t[:, 2] - t[:, 0]) \
        + 0.01 * n


def seen_mask(points: np.ndarray, poses: list[np.ndarray], caster, config: StreetConfig,
              resolution: int = 512) -> np.ndarray:
    k = config.intrinsics(resolution)
    seen = np.zeros(len(points), dtype=bool)
    for pose in poses:
        uv, depth = project_world_to_image(points, k, pose)
        inside = (depth > 0) & (uv[:, 0] >= 0) & (uv[:, 0] < k.width) & (uv[:, 1] >= 0) \
            & (uv[:, 1] < k.height) & ~seen
        if not inside.any():
            continue
        eye = pose[:3, 3]
        to = points[inside] - eye
        _, t = caster.first_hit(np.broadcast_to(eye, to.shape), to)
        ok = t >= 1 - 0.01 / np.linalg.norm(to, axis=1)
        idx = np.flatnonzero(inside)
        seen[idx[ok]] = True
    return seen


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("ids", nargs="*", help="building ids (default: all)")
    p.add_argument("--no-context", action="store_true")
    p.add_argument("--out", type=Path)
    args = p.parse_args()
    context = not args.no_context
    config = StreetConfig()
    entries = [e for e in lod3_entries() if not args.ids or e.id in args.ids]
    lines = ["| building | stations | frames | covered facades | seen (>= 50 %) | "
             "area seen | plan s |", "|---|---|---|---|---|---|---|"]
    totals = []
    for e in entries:
        building = build_lod3_building(e.id, e.file)
        start = time.time()
        poses = street_views(building, config, context=context)
        plan_s = time.time() - start
        stations = len(street_stations(building, config).positions_m)
        caster, _ = scene_caster(building, with_neighbours=context)
        rng = np.random.default_rng(0)
        shares, areas = [], []
        for f in building.truth.facades:
            shares.append(float(seen_mask(facade_points_m(building, f.id, rng), poses, caster,
                                          config).mean()))
            areas.append(f.facade_area_m2)
        shares_a, areas_a = np.array(shares), np.array(areas)
        seen = int((shares_a >= SEEN).sum())
        cover = float((shares_a * areas_a).sum() / areas_a.sum())
        totals.append((len(poses), seen, len(shares), cover))
        lines.append(f"| {e.id} | {stations} | {len(poses)} | {len(shares)} | {seen} | "
                     f"{cover:.2f} | {plan_s:.1f} |")
        print(lines[-1], flush=True)
    frames = np.array([t[0] for t in totals])
    lines.append(f"\n{len(totals)} buildings, context {context}: frames median "
                 f"{np.median(frames):.0f} (min {frames.min()}, max {frames.max()}); covered "
                 f"facades seen {sum(t[1] for t in totals)} / {sum(t[2] for t in totals)}; "
                 f"area seen median {np.median([t[3] for t in totals]):.2f}")
    print(lines[-1])
    if args.out:
        args.out.write_text("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
