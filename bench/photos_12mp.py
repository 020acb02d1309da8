"""The photos source on 100 photos of 12 MP: time per stage, and the pose error against the
truth when the photos are renders; prints a Markdown table.

    python bench/photos_12mp.py [--photos DIR] [--work DIR] [--workers N] [--views N]
        [--max-image-px PX] [--max-features N] [--exhaustive]

Without ``--photos`` it renders, once (kept in ``--work``, resumed where it stopped), 100
orbit views of 4000 x 3000 px of the tiny preset's ``tiny_l_shaped`` in the photo look
(``dataset.rendering``; the default orbit's cameras, 60 degrees across, planned for the 4:3
frame, named in the order of their bearing round the building as a walk round it takes
them; an orbit is what structure from motion posed best, docs/measurements/photo-look.md),
strips them to JPEG photos with camera EXIF
(:func:`dataset.importers.photos.stripped_renders.strip_renders`) and poses them with
``--known-distance`` between the first photo and the one farthest from it
(:func:`~dataset.importers.photos.stripped_renders.known_pair`). Rendering is setup, not
part of the timed path (about 27 CPU seconds a view, in ``--workers`` processes). The
table's seconds are the photos source's own stages
(:mod:`dataset.importers.photos.stage_times`), read from the scene's ``photos`` record: wall
seconds, and in brackets the CPU seconds the process spent in them (threads included),
which other work on shared cores does not change. ``--views N`` poses N of the 100 views,
evenly spaced (a quick run). ``--max-image-px`` and ``--max-features`` set the
structure-from-motion options of :class:`dataset.importers.photos.sfm.SfmConfig` (default:
its defaults); ``--exhaustive`` matches every pair instead of the pairs preemptive matching
keeps (the default; the table's "pairs matched"). With ``--photos DIR`` (a folder of
photos) it poses those instead, with a stand-in ``--known-height`` of 10 m (the scale does
not change the time), and reports no pose error.
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench.tables import markdown_table  # noqa: E402
from dataset.generate import scene_seed  # noqa: E402
from dataset.importers.photos.metric_frame import ScaleHint  # noqa: E402
from dataset.importers.photos.photo_folder import list_photos  # noqa: E402
from dataset.importers.photos.pose_error import pose_errors  # noqa: E402
from dataset.importers.photos.preemptive_pairs import ExhaustiveMatching  # noqa: E402
from dataset.importers.photos.sfm import SfmConfig  # noqa: E402
from dataset.importers.photos.source import RECORD_KEY, PhotosOptions, read_photos  # noqa: E402
from dataset.importers.photos.stage_times import (  # noqa: E402
    CPU_SECONDS_KEY,
    SECONDS_KEY,
    STAGES,
    TOTAL_KEY,
)
from dataset.importers.photos.stripped_renders import (  # noqa: E402
    known_pair,
    strip_renders,
    stripped_poses,
)
from dataset.importers.source import BuildingEntry, NoOptions, write_scenes  # noqa: E402
from dataset.rendering.context import ViewMeshes  # noqa: E402
from dataset.rendering.orbit_views import (  # noqa: E402
    OrbitConfig,
    point_of_interest_m,
    sample_orbit_views,
)
from dataset.rendering.render import render_view  # noqa: E402
from dataset.rendering.shading import RgbConfig  # noqa: E402
from dataset.scenes.scene_writer import GenerateConfig  # noqa: E402
from dataset.sources import PRESET_SOURCE  # noqa: E402
from envelope.camera import Intrinsics  # noqa: E402
from envelope.executors.worker_pool import worker_pool  # noqa: E402
from envelope.protocols import TRAIN_PROTOCOL  # noqa: E402
from envelope.scene_record import Frame, Scene  # noqa: E402
from envelope.scenes.images import write_rgb  # noqa: E402
from envelope.scenes.scene import read_scene, write_transforms  # noqa: E402

PRESET, BUILDING = "tiny", "tiny_l_shaped"
PHOTOS = 100
WIDTH_PX, HEIGHT_PX = 4000, 3000  # 12 MP, a phone's 4:3 frame
STRIP_ROWS = 375
"""Rows rendered at once: a whole 12 MP view's rays take gigabytes and spend a third of its
time in the kernel; strips of 375 rows give the same pixels (the shading is per ray)."""
HEIGHT_STAND_IN_M = 10.0
"""``--photos``' scale: any scale poses the photos in the same time."""
COLUMNS = ("photos", "pixels", "posed", "pairs matched", *(s.label for s in STAGES), "total s",
           "rotation deg (median / max)", "position m (median / max)", "scale error %")


def render_views(images_dir: Path, entry: BuildingEntry, seed: int, frames: list[Frame],
                 workers: int) -> None:
    """Render the RGB image of each of ``frames`` not yet in ``images_dir`` (each written
    whole or not at all, so a stopped render resumes), in ``workers`` processes."""
    images_dir.mkdir(parents=True, exist_ok=True)
    todo = [(entry, seed, images_dir, f) for f in frames
            if not (images_dir / Path(f.file_path).name).is_file()]
    if not todo:
        return
    start = time.perf_counter()
    with worker_pool(workers) as pool:
        for done, name in enumerate(pool.imap(_render_frame, todo), 1):
            print(f"rendered {name} ({done}/{len(todo)}, {time.perf_counter() - start:.0f} s)",
                  file=sys.stderr)


def planned_capture() -> tuple[BuildingEntry, int, list[Frame]]:
    """The building's preset entry, its seed and the capture's frames (module docstring),
    in the order of their bearing from the building's centre."""
    entry, = (e for e in PRESET_SOURCE.read(PRESET, NoOptions()) if e.name == BUILDING)
    building = entry.build()
    seed = scene_seed(0, entry.seed) if entry.seed is not None else 0
    k = Intrinsics.from_fov(WIDTH_PX, HEIGHT_PX, GenerateConfig().fov_deg)
    caster = ViewMeshes(building, context=False).alone
    poses = sample_orbit_views(building, caster, k, PHOTOS, config=OrbitConfig(), seed=seed)
    centre = point_of_interest_m(caster)
    poses.sort(key=lambda p: float(np.arctan2(*(p[:2, 3] - centre[:2])[::-1])))
    return entry, seed, [Frame(f"images/{TRAIN_PROTOCOL}_{i:04d}.png", pose, k, TRAIN_PROTOCOL)
                         for i, pose in enumerate(poses)]


def _render_frame(job: tuple) -> str:
    entry, seed, images_dir, frame = job
    meshes = ViewMeshes(entry.build(), context=False)
    k = frame.intrinsics
    strips = []
    for row in range(0, k.height, STRIP_ROWS):
        strip_k = Intrinsics(k.fx, k.fy, k.cx, k.cy - row, k.width, min(STRIP_ROWS, k.height - row))
        strips.append(render_view(meshes.rendered, strip_k, frame.world_from_camera,
                                  config=RgbConfig(look="photo"), seed=seed,
                                  textures=meshes.textures)[1])
    path = images_dir / Path(frame.file_path).name
    partial = path.with_suffix(".partial.png")
    write_rgb(partial, np.concatenate(strips))
    os.replace(partial, path)
    return path.name


def pose_capture(photos_dir: Path, out_root: Path, scale: ScaleHint,
                 sfm: SfmConfig) -> tuple[Path, dict]:
    """Run the photos source on ``photos_dir`` into ``out_root`` (replaced); return the
    scene folder and its ``photos`` record."""
    scene_dir, = write_scenes(read_photos(photos_dir, PhotosOptions(scale=scale, sfm=sfm,
                                                                    progress=False)),
                              out_root, overwrite=True, progress=False)
    return scene_dir, read_scene(scene_dir).extra[RECORD_KEY]


def table_row(photos_dir: Path, scene_dir: Path, record: dict,
              truth: dict[str, np.ndarray] | None) -> list[str]:
    """One row of the table: the photos, their size, how many were posed, the wall (and CPU)
    seconds per stage and the pose error (``truth``: the true poses by photo name, or
    ``None``)."""
    photos = list_photos(photos_dir)
    sizes = sorted({(p.width, p.height) for p in photos})
    megapixels = max(w * h for w, h in sizes) / 1e6
    pixels = ", ".join(f"{w} x {h}" for w, h in sizes) + f" ({megapixels:.1f} MP)"
    wall, cpu = record[SECONDS_KEY], record[CPU_SECONDS_KEY]
    posed = record["posed"]
    row = [str(len(photos)), pixels, f"{posed} ({100 * posed / len(photos):.0f} %)",
           f"{record['matched_pairs']} of {record['all_pairs']}",
           *(f"{wall.get(key, 0.0):.0f} ({cpu.get(key, 0.0):.0f})"
             for key in [s.key for s in STAGES] + [TOTAL_KEY])]
    if truth is None:
        return row + ["-", "-", "-"]
    frames = read_scene(scene_dir).frames
    names = [Path(f.file_path).name for f in frames]
    e = pose_errors(np.stack([f.world_from_camera for f in frames]),
                    np.stack([truth[n] for n in names]))
    return row + [f"{np.median(e.rotation_deg):.3f} / {e.rotation_deg.max():.3f}",
                  f"{np.median(e.position_m):.3f} / {e.position_m.max():.3f}",
                  f"{100 * e.scale_error:.2f}"]


def stripped_capture(work: Path, workers: int, views: int) -> tuple[Path, dict[str, np.ndarray]]:
    """``views`` of the capture's photos (evenly spaced by bearing; module docstring), rendered
    where they are not yet, stripped into a folder under ``work`` (made once); return it and
    their true poses by photo name."""
    entry, seed, frames = planned_capture()
    # Every fourth view first, then every second, then the rest: a stopped render leaves
    # views spread round the building, which --views 25 or 50 poses.
    chosen = sorted({round(i * PHOTOS / views) for i in range(views)},
                    key=lambda i: (i % 4 != 0, i % 2 != 0, i))
    scene_dir = work / f"renders-{views}" / BUILDING  # a scene of the chosen views
    photos_dir = work / f"photos-{views}" / BUILDING
    if not (scene_dir / "transforms.json").is_file():
        images_dir = work / "renders" / BUILDING / "images"
        render_views(images_dir, entry, seed, [frames[i] for i in chosen], workers)
        (scene_dir / "images").mkdir(parents=True, exist_ok=True)
        for i in chosen:
            name = Path(frames[i].file_path).name
            if not (scene_dir / "images" / name).is_file():
                os.link(images_dir / name, scene_dir / "images" / name)
        write_transforms(scene_dir, Scene(scene_dir, tuple(frames[i] for i in sorted(chosen))))
    if not photos_dir.is_dir():
        partial = photos_dir.with_name(photos_dir.name + ".partial")
        shutil.rmtree(partial, ignore_errors=True)
        strip_renders(scene_dir, partial, (TRAIN_PROTOCOL,))
        partial.rename(photos_dir)
    return photos_dir, stripped_poses(scene_dir, (TRAIN_PROTOCOL,))


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--photos", type=Path, help="a folder of photos to pose instead of the "
                   "rendered capture (no pose error)")
    p.add_argument("--work", type=Path, default=Path("data/bench/photos-12mp"),
                   help="where the renders, photos and posed scenes are kept (default "
                   "data/bench/photos-12mp)")
    p.add_argument("--workers", type=int, default=2, help="render processes (default 2)")
    p.add_argument("--views", type=int, default=PHOTOS, help=f"pose only this many of the "
                   f"{PHOTOS} views, evenly spaced (a quick run; default {PHOTOS})")
    defaults = SfmConfig()
    p.add_argument("--max-image-px", type=int, default=defaults.max_image_px,
                   help=f"SfmConfig.max_image_px (default {defaults.max_image_px})")
    p.add_argument("--max-features", type=int, default=defaults.max_features,
                   help=f"SfmConfig.max_features (default {defaults.max_features})")
    p.add_argument("--exhaustive", action="store_true", help="match every pair (default: "
                   "preemptive matching, SfmConfig.matching)")
    args = p.parse_args(argv)
    if not 3 <= args.views <= PHOTOS:
        p.error(f"--views must be 3 to {PHOTOS}")
    sfm = replace(defaults, max_image_px=args.max_image_px, max_features=args.max_features,
                  **({"matching": ExhaustiveMatching()} if args.exhaustive else {}))
    if args.photos is None:
        photos_dir, truth = stripped_capture(args.work, args.workers, args.views)
        scale = ScaleHint(known_distance=known_pair(truth))
    else:
        photos_dir, truth = args.photos, None
        scale = ScaleHint(known_height_m=HEIGHT_STAND_IN_M)
    load = os.getloadavg()[0]
    scene_dir, record = pose_capture(photos_dir, args.work / "posed", scale, sfm)
    print(f"load average (1 min) {load:.1f} before, {os.getloadavg()[0]:.1f} after, on "
          f"{os.cpu_count()} cores; {sfm}", file=sys.stderr)
    print(markdown_table(f"Photos source on {photos_dir.name}", COLUMNS,
                         [table_row(photos_dir, scene_dir, record, truth)]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
