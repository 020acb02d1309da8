"""A small rendered scene folder for the neural3d tests (exact renderer, no generator needed).

Cameras sit on a ring of elevations around the building and look at its centre;
frames alternate into the train and eval splits.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from dataset.rendering.render import Raycaster, RgbConfig, render_ground_truth, render_rgb
from envelope.camera import Intrinsics, look_at
from envelope.scene_record import Frame, Scene
from envelope.scenes.images import write_depth_m, write_labels, write_rgb
from envelope.scenes.scene import write_transforms
from envelope.truth import Building


def write_ring_scene(building: Building, root: Path, *, size_px: int = 40, n_train: int = 24,
                     n_eval: int = 2, distance_m: float = 40.0, fov_deg: float = 50.0,
                     split: str = "train") -> Path:
    """Render ``n_train + n_eval`` views of ``building`` into a scene folder at ``root``; the
    training views go to ``split`` (``train``: the orbit, or ``street``)."""
    root = Path(root)
    lo, hi = building.mesh.vertices_m.min(0), building.mesh.vertices_m.max(0)
    target = (lo + hi) / 2
    k = Intrinsics.from_fov(size_px, size_px, fov_deg)
    caster = Raycaster(building.mesh)
    frames = []
    n = n_train + n_eval
    for i in range(n):
        azimuth = 2 * np.pi * i / n + 0.3
        elevation = np.deg2rad(12 + 45 * ((i * 7) % n) / n)
        eye = target + distance_m * np.array([np.cos(azimuth) * np.cos(elevation),
                                              np.sin(azimuth) * np.cos(elevation),
                                              np.sin(elevation)])
        pose = look_at(eye, target)
        gt = render_ground_truth(caster, k, pose)
        rgb = render_rgb(caster, k, pose, config=RgbConfig(shadows=False), seed=0)
        name = f"{i:03d}.png"
        write_rgb(root / "images" / name, rgb)
        write_labels(root / "semantics" / name, gt.labels)
        write_depth_m(root / "depth" / name, gt.depth_z_m, 0.001)
        frames.append(Frame(
            file_path=f"images/{name}", world_from_camera=pose, intrinsics=k,
            split="eval" if i % (n // max(n_eval, 1)) == 1 and n_eval else split,
            semantic_file_path=f"semantics/{name}", depth_file_path=f"depth/{name}",
        ))
    write_transforms(root, Scene(root=root, frames=tuple(frames)))
    return root
