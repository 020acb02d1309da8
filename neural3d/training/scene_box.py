"""The scene box: the visual hull of the train views' foreground masks, carved on a voxel grid.

A voxel is carved when some camera sees it and its whole bounding sphere
projects onto background pixels, or when fewer than half the views see it;
what survives bounds the building. Only the
inputs of training (poses, intrinsics, semantic masks) are used, never the
ground truth, and no unit-sphere assumption is made.
"""

from __future__ import annotations

from collections.abc import Sequence

import cv2
import numpy as np

from envelope.camera import Intrinsics, project_world_to_image


def visual_hull_box_m(
    intrinsics: Sequence[Intrinsics],
    world_from_camera: Sequence[np.ndarray],
    foreground: Sequence[np.ndarray],
    *,
    resolution: int = 64,
    margin: float = 0.1,
    ground_z_m: float | None = 0.0,
    min_view_fraction: float = 0.5,
) -> tuple[np.ndarray, np.ndarray]:
    """World box (m) around everything the masks may show as foreground.

    Parameters
    ----------
    intrinsics, world_from_camera : one per view; poses are (4, 4) OpenGL camera-to-world.
    foreground : one (H, W) bool mask per view, True where the building is.
    resolution : voxels along the longest side of the search box.
    margin : fraction of the hull box's longest side added on each side.
    ground_z_m : the hull is cut below this height (the ground plane), None to keep it.
    min_view_fraction : a voxel seen by fewer views than this fraction is left out.

    Returns
    -------
    box_min_m, box_max_m : (3,) float64 world corners.
    """
    if not (len(intrinsics) == len(world_from_camera) == len(foreground)) or not intrinsics:
        raise ValueError("visual_hull_box_m needs one intrinsics, pose and mask per view (>= 1)")
    for k, m in zip(intrinsics, foreground):
        if m.shape != (k.height, k.width):
            raise ValueError(f"mask shape {m.shape} does not match image size {k.height}x{k.width}")
    if not any(m.any() for m in foreground):
        raise ValueError("no foreground pixel in any mask: the scene shows no building")
    centres = np.stack([np.asarray(p)[:3, 3] for p in world_from_camera])
    lo, hi = centres.min(0), centres.max(0)
    pad = 0.5 * np.max(hi - lo) + 1.0  # the building may reach past the cameras' span
    lo, hi = lo - pad, hi + pad
    if ground_z_m is not None:
        lo[2] = max(lo[2], ground_z_m)
    dist_px = [cv2.distanceTransform((~m).astype(np.uint8), cv2.DIST_L2, 5) for m in foreground]
    views = list(zip(intrinsics, world_from_camera, dist_px))
    min_views = max(1, min_view_fraction * len(views))
    box_lo, box_hi = _carve(lo, hi, resolution, views, min_views)
    # Second pass inside the first hull's box (plus a voxel): a finer, tighter box.
    pad = np.max(box_hi - box_lo) / resolution
    lo, hi = box_lo - pad, box_hi + pad
    if ground_z_m is not None:
        lo[2] = max(lo[2], ground_z_m)
    box_lo, box_hi = _carve(lo, hi, resolution, views, min_views)
    extra = margin * np.max(box_hi - box_lo)
    return box_lo - extra, box_hi + extra


def _carve(lo: np.ndarray, hi: np.ndarray, resolution: int,
           views: list[tuple[Intrinsics, np.ndarray, np.ndarray]],
           min_views: float) -> tuple[np.ndarray, np.ndarray]:
    """Bounding box of the voxels of [lo, hi] that survive carving."""
    voxel_m = np.max(hi - lo) / resolution
    axes = [np.arange(lo[i] + voxel_m / 2, hi[i], voxel_m) for i in range(3)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    keep = np.ones(len(grid), dtype=bool)
    seen_count = np.zeros(len(grid), dtype=np.int64)
    radius_m = voxel_m * np.sqrt(3) / 2
    for k, pose, dist_px in views:
        # dist_px: distance (px) from each pixel to the nearest foreground pixel.
        uv, depth = project_world_to_image(grid[keep], k, pose)
        u, v = uv[:, 0], uv[:, 1]
        inside = (depth > radius_m) & (u >= 0) & (u < k.width) & (v >= 0) & (v < k.height)
        iu = np.clip(u[inside].astype(int), 0, k.width - 1)
        iv = np.clip(v[inside].astype(int), 0, k.height - 1)
        r_px = k.fx * radius_m / depth[inside] + 1.5  # +1.5 px: pixel rounding
        carve = np.zeros(len(uv), dtype=bool)
        carve[np.flatnonzero(inside)] = dist_px[iv, iu] > r_px
        idx = np.flatnonzero(keep)
        seen_count[idx[inside]] += 1
        keep[idx[carve]] = False
    # A point between a camera and the building projects onto the building in the few
    # views that see it; the building itself is in (nearly) every view of cameras that
    # look at it. So a kept voxel must also be seen by enough views.
    keep &= seen_count >= min_views
    if not keep.any():
        raise ValueError("the masks' visual hull is empty: check poses and intrinsics")
    kept = grid[keep]
    return kept.min(0) - voxel_m / 2, kept.max(0) + voxel_m / 2
