"""Depth images for a photos scene: each posed photo's piecewise-planar depth from the sparse
points it observes (:mod:`dataset.importers.photos.sparse_depth`), written as the rendered
scenes write theirs (``depth/<photo stem>.png``, 16-bit, value x
``depth_unit_scale_factor`` = z-depth in metres, 0 = none).

A photo from an input without points (a nerfstudio ``transforms.json``), or one that
observes fewer than 3 points, gets no depth image (``depth_file_path`` absent): the 2D
methods skip such a view and say why. The scene's depth unit is 1 mm unless its farthest
point needs a coarser one to fit 16 bits (then whole millimetres, as fine as fits).
"""

from __future__ import annotations

import math
from collections import Counter
from concurrent.futures import ThreadPoolExecutor
from dataclasses import replace
from functools import partial
from pathlib import Path

import numpy as np

from dataset.importers.photos.metric_frame import Similarity
from dataset.importers.photos.posed import PosedPhoto
from dataset.importers.photos.sparse_depth import SparseDepthConfig, piecewise_planar_depth_z_m
from envelope.scene_record import DEFAULT_DEPTH_UNIT_M, Frame, Scene
from envelope.scenes.images import write_depth_m

DEPTH_FOLDER = "depth"
DEPTH_RECORD_KEY = "depth"
DEPTH_SOURCE = ("sparse points each photo observes (structure from motion), joined into "
                "planar triangles in the image (Delaunay; inverse depth linear); 0 outside "
                "their hull and in triangles seen edge-on")
MAX_UNITS = 65535  # a 16-bit PNG's largest value


def with_photo_depths(scene: Scene, photos: tuple[PosedPhoto, ...], similarity: Similarity,
                      record_key: str, config: SparseDepthConfig | None = None,
                      threads: int = 1) -> Scene:
    """Write the depth image of each of ``scene``'s frames (``photos`` in the same order,
    their points taken to the scene's frame by ``similarity``) under ``scene.root``; return
    the scene with their ``depth_file_path``, its depth unit, and a ``depth`` entry in its
    ``extra[record_key]`` record (how depth was made, how many photos have it, the median
    points per photo and share of pixels with depth). ``config``: ``None`` for the default;
    ``threads``: photos worked on at once (triangulating, filling and encoding a depth image
    leave Python's lock for much of their time).

    Raises
    ------
    ValueError
        ``photos`` do not match the frames, or two photos with points share a file stem
        (their depth images would too).
    """
    config = SparseDepthConfig() if config is None else config
    if len(photos) != len(scene.frames):
        raise ValueError(f"{len(photos)} photos for {len(scene.frames)} frames")
    points = [None if p.observed_points is None else similarity.points(p.observed_points)
              for p in photos]
    with_points = [p.name for p, pts in zip(photos, points) if pts is not None and len(pts) >= 3]
    clashes = sorted(s for s, n in Counter(Path(n).stem for n in with_points).items() if n > 1)
    if clashes:
        raise ValueError(f"photos {', '.join(clashes)} share a file name stem (e.g. a.jpg and "
                         "a.png); their depth images would too: rename one")
    unit_m = depth_unit_m(max((_farthest_m(pts, f.world_from_camera)
                               for f, pts in zip(scene.frames, points) if pts is not None),
                              default=0.0))
    if with_points:
        (scene.root / DEPTH_FOLDER).mkdir(exist_ok=True)
    with ThreadPoolExecutor(max(1, threads)) as pool:
        done = list(pool.map(partial(_with_depth, scene.root, unit_m, config),
                             scene.frames, points))
    frames = [frame for frame, _, _ in done]
    counts = [count for _, count, _ in done if count]
    shares = [share for _, count, share in done if count]
    record = {"source": DEPTH_SOURCE, "photos_with_depth": len(counts),
              "max_incidence_deg": config.max_incidence_deg}
    if counts:
        record |= {"points_per_photo_median": int(np.median(counts)),
                   "pixels_with_depth_median": round(float(np.median(shares)), 4)}
    extra = {**scene.extra, record_key: {**scene.extra.get(record_key, {}),
                                         DEPTH_RECORD_KEY: record}}
    return replace(scene, frames=tuple(frames), depth_unit_scale_factor=unit_m, extra=extra)


def _with_depth(root: Path, unit_m: float, config: SparseDepthConfig, frame: Frame,
                points_m: np.ndarray | None) -> tuple[Frame, int, float]:
    """``frame`` with its depth image written under ``root`` (``points_m``: (N, 3) the
    points it observes, scene frame), the number of points and the share of pixels with
    depth; the frame unchanged, 0 and 0.0 when it has fewer than 3 points."""
    if points_m is None or len(points_m) < 3:
        return frame, 0, 0.0
    depth = piecewise_planar_depth_z_m(points_m, frame.intrinsics, frame.world_from_camera,
                                       config)
    relative = f"{DEPTH_FOLDER}/{Path(frame.file_path).stem}.png"
    write_depth_m(root / relative, depth, unit_m)
    return (replace(frame, depth_file_path=relative), len(points_m),
            float(np.mean(depth > 0)))


def depth_unit_m(max_depth_m: float) -> float:
    """The depth unit (m) for depths up to ``max_depth_m``: 1 mm, or the smallest whole
    number of millimetres that holds it in 16 bits."""
    if max_depth_m <= MAX_UNITS * DEFAULT_DEPTH_UNIT_M:
        return DEFAULT_DEPTH_UNIT_M
    return math.ceil(max_depth_m / (MAX_UNITS * DEFAULT_DEPTH_UNIT_M)) * DEFAULT_DEPTH_UNIT_M


def _farthest_m(points_world_m: np.ndarray, world_from_camera: np.ndarray) -> float:
    """The largest z-depth of (N, 3) points seen from a pose (0 without points): no depth
    interpolated between them exceeds it."""
    if len(points_world_m) == 0:
        return 0.0
    camera_from_world = np.linalg.inv(np.asarray(world_from_camera, dtype=np.float64))
    z_m = -(points_world_m @ camera_from_world[2, :3] + camera_from_world[2, 3])
    return float(z_m.max())
