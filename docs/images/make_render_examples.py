"""Example frames for docs/rendering.md: ``python docs/images/make_render_examples.py``.

One 256 x 256 view per building family (the ``tiny`` preset's buildings), as
four PNGs side by side: RGB, z-depth (turbo colour map, near = red), world
normals ((n + 1) / 2 as RGB) and semantic classes (palette below).
"""

from __future__ import annotations

import sys
from pathlib import Path

import cv2
import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from dataset.presets import build_building, preset_recipes  # noqa: E402
from dataset.rendering.orbit_views import point_of_interest_m  # noqa: E402
from dataset.rendering.render import Raycaster, render_view  # noqa: E402
from envelope.camera import Intrinsics, look_at  # noqa: E402

# background, wall, window, roof, door, other (RGB)
PALETTE = np.array([[0, 0, 0], [190, 190, 190], [40, 120, 230], [200, 60, 50],
                    [240, 190, 40], [90, 200, 90]], dtype=np.uint8)
SIZE = 256


def example_panels(family: str) -> np.ndarray:
    """(SIZE, 4 * SIZE, 3) uint8 RGB | depth | normals | semantics of one building."""
    recipe = next(r for r in preset_recipes("tiny") if r.family == family)
    building = build_building(recipe)
    rc = Raycaster(building.mesh)
    k = Intrinsics.from_fov(SIZE, SIZE, 60.0)
    poi = point_of_interest_m(rc)
    radius = 0.62 * float(np.linalg.norm(np.ptp(rc.bounds_m, axis=0))) / np.tan(np.deg2rad(30))
    azimuth, elevation = np.deg2rad(-60.0), np.deg2rad(18.0)
    eye = poi + radius * np.array([np.cos(elevation) * np.cos(azimuth),
                                   np.cos(elevation) * np.sin(azimuth), np.sin(elevation)])
    gt, rgb = render_view(rc, k, look_at(eye, poi), seed=recipe.seed, supersampling=2)
    hit = gt.depth_z_m > 0
    d = gt.depth_z_m
    lo, hi = d[hit].min(), d[hit].max()
    scaled = np.zeros(d.shape, np.uint8)
    scaled[hit] = np.round(255 * (1 - (d[hit] - lo) / max(hi - lo, 1e-9)))
    depth = cv2.applyColorMap(scaled, cv2.COLORMAP_TURBO)[..., ::-1]
    depth[~hit] = 0
    normals = np.where(hit[..., None], np.round((gt.normals_world + 1) * 127.5), 0)
    semantics = PALETTE[gt.labels]
    return np.concatenate([rgb, depth, normals.astype(np.uint8), semantics], axis=1)


def main() -> int:
    out = Path(__file__).resolve().parent
    for family in ("skyscraper", "l_shaped", "realistic"):
        panels = example_panels(family)
        path = out / f"render_{family}.png"
        cv2.imwrite(str(path), np.ascontiguousarray(panels[..., ::-1]),
                    [cv2.IMWRITE_PNG_COMPRESSION, 9])
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
