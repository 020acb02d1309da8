"""How good a photos scene's depth from sparse points is, and what the 2D methods make of it
(issue 47): a procedural building rendered in the photo look, stripped of its poses and
posed by the photos source (dataset.importers.photos.stripped_renders), whose depth
(dataset.importers.photos.photo_depth) is compared with the renders' true depth; then 2D-S
and 2D-SS find their own facades on the photos scene, with the true masks carried over to
its photos, and on the rendered scene's own train views (true poses and depth), both scored
against the truth.

    python -m bench.photos_depth --building tiny_l_shaped --resolution 512 --views 32 \\
        --work /tmp/photos-depth

Depth is compared point by point: each photo pixel with depth is put in the world by the
photos scene's camera, taken to the true frame by the similarity that best takes the posed
camera centres onto the true ones, and projected into the true camera, where the render's
depth and class are read (nearest pixel). Coverage: the share of each class's pixels (the
true class, carried over by the same projection at the render's median depth: the cameras
differ by about 5 cm) that have depth. The masks given to the methods are carried over the
same way (exact up to about a pixel).
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from baselines.wwr2ds import Wwr2dsConfig, run_2ds
from baselines.wwr2dss import Wwr2dssConfig, run_2dss
from bench.tables import markdown_table
from dataset.generate import generate_preset
from dataset.importers.photos.pose_error import similarity_alignment
from dataset.importers.photos.stripped_renders import pose_stripped_renders
from dataset.rendering.orbit_views import OrbitConfig
from dataset.rendering.shading import RgbConfig
from dataset.scenes.scene_writer import GenerateConfig
from envelope.camera import pixel_centres, project_world_to_image, unproject_depth_to_world
from envelope.classes import SemanticClass
from envelope.results import MethodResult
from envelope.scene_record import Frame, Scene
from envelope.scenes.images import write_labels
from envelope.scenes.scene import read_method_input, read_scene, write_transforms
from envelope.scenes.scene_validation import read_frame_depth_m, read_frame_labels
from metrics.score.errors import building_errors, facade_errors

CLASSES = (SemanticClass.WALL, SemanticClass.WINDOW, SemanticClass.ROOF)


class ToTrue:
    """The similarity taking the photos scene's frame to the true one (from camera centres)."""

    def __init__(self, photos: Scene, true_pose_by_stem: dict[str, np.ndarray]):
        posed = np.stack([f.world_from_camera for f in photos.frames])
        true = np.stack([true_pose_by_stem[Path(f.file_path).stem][:3, 3]
                         for f in photos.frames])
        self.scale, self.rotation, self.shift = similarity_alignment(posed[:, :3, 3], true)

    def points(self, p: np.ndarray) -> np.ndarray:
        return self.scale * p @ self.rotation.T + self.shift


def _to_true_pixels(photos: Scene, frame: Frame, true_frame: Frame, to_true: ToTrue,
                    depth_z_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(H, W, 2) int pixels of the true image (clipped) for each photo pixel at the given
    z-depth, and (H, W) the points' z-depth in the true camera."""
    world = unproject_depth_to_world(pixel_centres(frame.intrinsics), depth_z_m,
                                     frame.intrinsics, frame.world_from_camera)
    uv, z = project_world_to_image(to_true.points(world), true_frame.intrinsics,
                                   true_frame.world_from_camera)
    k = true_frame.intrinsics
    cols = np.clip(np.floor(uv[..., 0]), 0, k.width - 1).astype(int)
    rows = np.clip(np.floor(uv[..., 1]), 0, k.height - 1).astype(int)
    inside = (uv[..., 0] >= 0) & (uv[..., 0] < k.width) & (uv[..., 1] >= 0) \
        & (uv[..., 1] < k.height)
    return np.stack([rows, cols, inside], axis=-1), z


def compare_depth(photos: Scene, rendered: Scene, to_true: ToTrue) -> dict[str, dict]:
    """Per class: pixels, share with depth, median and 90th percentile |depth error| (m);
    also writes each photo's carried-over true labels into the photos scene."""
    by_stem = {Path(f.file_path).stem: f for f in rendered.frames}
    stats = {c.name.lower(): {"pixels": 0, "with_depth": 0, "errors": []} for c in CLASSES}
    frames = []
    (photos.root / "semantics").mkdir(exist_ok=True)
    for frame in photos.frames:
        true_frame = by_stem[Path(frame.file_path).stem]
        true_depth = read_frame_depth_m(rendered, true_frame)
        true_labels = read_frame_labels(rendered, true_frame)
        nominal = np.full((frame.intrinsics.height, frame.intrinsics.width),
                          float(np.median(true_depth[true_depth > 0])) / to_true.scale)
        where, _ = _to_true_pixels(photos, frame, true_frame, to_true, nominal)
        labels = np.where(where[..., 2] > 0, true_labels[where[..., 0], where[..., 1]],
                          SemanticClass.BACKGROUND).astype(np.uint8)
        relative = f"semantics/{Path(frame.file_path).stem}.png"
        write_labels(photos.root / relative, labels)
        frames.append(replace(frame, semantic_file_path=relative))
        depth = (read_frame_depth_m(photos, frame) if frame.depth_file_path
                 else np.zeros_like(nominal))
        at, z_m = _to_true_pixels(photos, frame, true_frame, to_true, depth)
        has = (depth > 0) & (at[..., 2] > 0)
        error = z_m - true_depth[at[..., 0], at[..., 1]]
        for c in CLASSES:
            s = stats[c.name.lower()]
            mine = labels == c
            s["pixels"] += int(mine.sum())
            s["with_depth"] += int((mine & has).sum())
            s["errors"].append(np.abs(error[mine & has]))
    write_transforms(photos.root, replace(photos, frames=tuple(frames)))
    out = {}
    for name, s in stats.items():
        e = np.concatenate(s["errors"])
        out[name] = {"pixels": s["pixels"], "coverage": s["with_depth"] / max(s["pixels"], 1),
                     "median_m": float(np.median(e)) if len(e) else None,
                     "p90_m": float(np.percentile(e, 90)) if len(e) else None}
    return out


def in_true_frame(result: MethodResult, to_true: ToTrue) -> MethodResult:
    """A photos-scene result's facades (normal, centre) and areas in the true frame."""
    s2 = to_true.scale ** 2
    facades = tuple(replace(
        f, normal=tuple(float(v) for v in to_true.rotation @ np.asarray(f.normal)),
        centre_m=tuple(float(v) for v in to_true.points(np.asarray(f.centre_m)[None])[0]),
        window_area_m2=None if f.window_area_m2 is None else f.window_area_m2 * s2,
        facade_area_m2=None if f.facade_area_m2 is None else f.facade_area_m2 * s2)
        for f in result.facades)
    return replace(result, facades=facades,
                   window_area_m2=None if result.window_area_m2 is None
                   else result.window_area_m2 * s2,
                   facade_area_m2=None if result.facade_area_m2 is None
                   else result.facade_area_m2 * s2)


def score_row(label: str, views: int, result: MethodResult, truth) -> list[object]:
    """Poses and depth, views, method, facades found, matched, missed, false positives,
    mean facade WWR error (points), building WWR and its truth, facade area APE (%)."""
    b = building_errors(result, truth)
    facades = facade_errors(result, truth)
    kinds = [f.kind for f in facades]
    points = [f.wwr_points for f in facades if f.kind == "matched" and f.wwr_points is not None]
    return [label, views, result.method, len(result.facades), kinds.count("matched"),
            kinds.count("missed"), kinds.count("false_positive"),
            f"{np.mean(points):.1f}" if points else "-", f"{b.wwr_est:.3f}",
            f"{b.wwr_true:.3f}", f"{b.facade_ape:.1f}"]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--preset", default="tiny")
    parser.add_argument("--building", default="tiny_l_shaped")
    parser.add_argument("--resolution", type=int, default=512)
    parser.add_argument("--views", type=int, default=32)
    parser.add_argument("--work", type=Path, required=True, help="an empty or missing folder")
    args = parser.parse_args(argv)
    config = GenerateConfig(resolution=args.resolution, views=args.views, ideal=False,
                            multi=False, orbit=OrbitConfig(elevation_deg=(15.0, 35.0)),
                            rgb=RgbConfig(look="photo"))
    scene_dir, = generate_preset(args.preset, args.work / "scenes", config,
                                 buildings=[args.building], progress=False)
    run = pose_stripped_renders(scene_dir, args.work / "work", ("train", "eval"))
    if run.failure:
        print(f"structure from motion failed: {run.failure}", file=sys.stderr)
        return 1
    rendered = read_scene(scene_dir)
    photos = read_scene(args.work / "work" / "posed" / scene_dir.name)
    to_true = ToTrue(photos, {Path(f.file_path).stem: f.world_from_camera
                              for f in rendered.frames})
    print(f"{scene_dir.name}: {run.posed} of {run.views} photos posed, scale "
          f"{abs(to_true.scale - 1):.2e} off; depth record {photos.extra['photos']['depth']}")
    depth_rows = [[name, st["pixels"], f"{100 * st['coverage']:.1f} %", f"{st['median_m']:.3f}",
                   f"{st['p90_m']:.3f}"]
                  for name, st in compare_depth(photos, rendered, to_true).items()]
    print(markdown_table("Depth from the sparse points against the renders' depth",
                         ("class", "pixels", "with depth", "median abs error (m)",
                          "90th percentile (m)"), depth_rows))
    truth = rendered.building
    on_photos = read_method_input(photos.root)
    on_renders = read_method_input(scene_dir)
    rows = []
    for run_one in (lambda s: run_2dss(s, "train", Wwr2dssConfig()),
                    lambda s: run_2ds(s, "train", Wwr2dsConfig())):
        rows.append(score_row("true, rendered", len(on_renders.frames_in("train")),
                              run_one(on_renders), truth))
        rows.append(score_row("recovered, sparse points", len(on_photos.frames_in("train")),
                              in_true_frame(run_one(on_photos), to_true), truth))
    print(markdown_table("Own facades on true masks", (
        "poses, depth", "views", "method", "facades", "matched", "missed", "false positives",
        "facade WWR error (points, mean)", "building WWR", "true WWR", "facade area APE (%)"),
        rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
