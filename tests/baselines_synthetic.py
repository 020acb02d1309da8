"""Closed-form images of a planar facade for the baselines' tests (not a test module).

The facade is the plane y = 0, x in [0, L], z in [0, H], facing -y (the
building is at y > 0). Windows are axis-aligned rectangles (x0, z0, x1, z1) in
it; their glass may be recessed by ``recess_m`` (the reveal reads as window).
With ``gable_m`` > 0 a triangular gable of that height tops the facade;
``balconies`` (z0, z1) are full-width class-"other" panels 1.2 m in front of it.
An optional neighbour facade at x = L, y in [0, neighbour_m], faces +x, and the
ground z = 0 is background with depth. Every image comes from ray-plane
intersections through pixel centres (envelope.camera.rays_world), so it is exact.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from envelope.camera import Intrinsics, look_at, rays_world
from envelope.classes import SemanticClass
from envelope.scene_record import Frame, Scene
from envelope.scenes.images import write_depth_m, write_labels, write_rgb
from envelope.scenes.scene import write_transforms

BALCONY_M = 1.2  # balcony panels stand this far in front of the facade
GROUND_RANGE_M = 50.0  # the ground ends here, so that depth fits a 16-bit PNG in mm


def window_grid(length_m: float, height_m: float, cols: int, rows: int, width_m: float,
                win_height_m: float) -> list[tuple[float, float, float, float]]:
    """Windows centred in a cols x rows grid of equal bays."""
    bay_w, bay_h = length_m / cols, height_m / rows
    out = []
    for i in range(cols):
        for j in range(rows):
            cx, cz = (i + 0.5) * bay_w, (j + 0.5) * bay_h
            out.append((cx - width_m / 2, cz - win_height_m / 2, cx + width_m / 2,
                        cz + win_height_m / 2))
    return out


def true_wwr(length_m, height_m, windows, gable_m: float = 0.0) -> float:
    area = length_m * height_m + 0.5 * length_m * gable_m
    return sum((x1 - x0) * (z1 - z0) for x0, z0, x1, z1 in windows) / area


def render_facade(intrinsics: Intrinsics, world_from_camera: np.ndarray, *, length_m: float,
                  height_m: float, windows, recess_m: float = 0.0,
                  neighbour_m: float = 0.0, gable_m: float = 0.0,
                  balconies=()) -> tuple[np.ndarray, np.ndarray]:
    """(H, W) uint8 labels and (H, W) float64 z-depth (m, 0 = none) of the facade scene."""
    o, d = rays_world(intrinsics, world_from_camera)
    hw = d.shape[:2]
    depth = np.full(hw, np.inf)
    labels = np.zeros(hw, dtype=np.uint8)
    with np.errstate(divide="ignore", invalid="ignore"):
        # ground z = 0 (background)
        t = -o[..., 2] / d[..., 2]
        hit = (t > 0) & (t < GROUND_RANGE_M)
        depth[hit] = t[hit]
        # front facade y = 0
        t = -o[..., 1] / d[..., 1]
        p = o + t[..., None] * d
        top = height_m + gable_m * (1 - np.abs(2 * p[..., 0] / length_m - 1))
        on = (t > 0) & (p[..., 0] >= 0) & (p[..., 0] <= length_m) & (p[..., 2] >= 0) & (
            p[..., 2] <= top)
        hit = on & (t < depth)
        depth[hit] = t[hit]
        labels[hit] = SemanticClass.WALL
        for x0, z0, x1, z1 in windows:
            win = hit & (p[..., 0] >= x0) & (p[..., 0] <= x1) & (p[..., 2] >= z0) & (
                p[..., 2] <= z1)
            labels[win] = SemanticClass.WINDOW
            if recess_m > 0:
                tg = (recess_m - o[..., 1]) / d[..., 1]
                g = o + tg[..., None] * d
                glass = win & (g[..., 0] >= x0) & (g[..., 0] <= x1) & (g[..., 2] >= z0) & (
                    g[..., 2] <= z1)
                depth[glass] = tg[glass]
        if neighbour_m > 0:
            t = (length_m - o[..., 0]) / d[..., 0]
            p = o + t[..., None] * d
            on = (t > 0) & (p[..., 1] >= 0) & (p[..., 1] <= neighbour_m) & (p[..., 2] >= 0) & (
                p[..., 2] <= height_m)
            hit = on & (t < depth)
            depth[hit] = t[hit]
            labels[hit] = SemanticClass.WALL
        for z0, z1 in balconies:  # class "other" panels 1.2 m in front, full facade width
            t = (-BALCONY_M - o[..., 1]) / d[..., 1]
            p = o + t[..., None] * d
            on = (t > 0) & (p[..., 0] >= 0) & (p[..., 0] <= length_m) & (p[..., 2] >= z0) & (
                p[..., 2] <= z1)
            hit = on & (t < depth)
            depth[hit] = t[hit]
            labels[hit] = SemanticClass.OTHER
    depth[~np.isfinite(depth)] = 0.0
    return labels, depth


def facade_pose(length_m: float, height_m: float, *, distance_m: float, azimuth_deg: float,
                eye_height_m: float = 1.6) -> np.ndarray:
    """world_from_camera looking at the facade centre from ``distance_m``, ``azimuth_deg``
    off the facade normal (positive: towards +x)."""
    a = np.deg2rad(azimuth_deg)
    centre = np.array([length_m / 2, 0.0, height_m / 2])
    eye = centre + distance_m * np.array([np.sin(a), -np.cos(a), 0.0])
    eye[2] = eye_height_m
    return look_at(eye, centre)


def write_facade_scene(root: Path, views: list[tuple[int, np.ndarray]], intrinsics: Intrinsics,
                       split: str = "ideal", **facade) -> Scene:
    """A scene folder with one frame per (facade_id, pose) in ``views``, rendered from the facade.

    Every frame shows the same synthetic facade (its facade_id is only a name here).
    """
    frames = []
    for n, (fid, pose) in enumerate(views):
        labels, depth = render_facade(intrinsics, pose, **facade)
        stem = f"{split}_{n:03d}.png"
        write_labels(root / "semantics" / stem, labels)
        write_depth_m(root / "depth" / stem, depth, 0.001)
        write_rgb(root / "images" / stem, np.stack([labels * 40] * 3, axis=-1).astype(np.uint8))
        frames.append(Frame(f"images/{stem}", pose, intrinsics, split, facade_id=fid,
                            depth_file_path=f"depth/{stem}",
                            semantic_file_path=f"semantics/{stem}"))
    scene = Scene(root=root, frames=tuple(frames))
    write_transforms(root, scene)
    return scene
