"""The photos source's scale, north and place from a city model, against the true cameras;
prints a Markdown table.

    python bench/photos_city_model.py --photos DIR --truth SCENE --split street
        --city-model FILE_OR_DIR [--city-building ID] --work DIR

``--photos``: a folder of stripped renders (:mod:`dataset.importers.photos.stripped_renders`)
whose true poses are the ``--split`` frames of the rendered scene ``--truth``. Structure
from motion runs once (the photos source's own settings, :class:`SfmConfig`) into the
COLMAP project ``WORK/colmap`` (kept: a rerun reuses it); the photos source then reads that
project twice, with ``--city-model`` and with ``--known-distance`` between the first photo
and the one farthest from it (from the true poses, as in bench/photos_from_renders.py), into
``WORK/city-model`` and ``WORK/known-distance``. For each: the scale error and the pose
errors after the best similarity (:mod:`dataset.importers.photos.pose_error`) and, for the
city model, which puts the scene in the building's frame that the rendered scene is in too
(``--citygml`` and the ``lod3`` preset import it so), the errors as they stand: heading
(the similarity's turn about z, deg), camera positions (m) and orientations (deg); the
fit's other fits (the record's ``alternatives``) go to stderr.
"""

from __future__ import annotations

import argparse
import shutil
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench.tables import markdown_table  # noqa: E402
from dataset.importers.photos.metric_frame import ScaleHint  # noqa: E402
from dataset.importers.photos.photo_folder import list_photos  # noqa: E402
from dataset.importers.photos.pose_error import (  # noqa: E402
    pose_errors,
    rotation_angle_deg,
    similarity_alignment,
)
from dataset.importers.photos.sfm import SfmConfig, reconstruct  # noqa: E402
from dataset.importers.photos.source import PhotosOptions, read_photos  # noqa: E402
from dataset.importers.photos.stripped_renders import known_pair, stripped_poses  # noqa: E402
from dataset.importers.source import write_scenes  # noqa: E402
from envelope.scenes.scene import read_scene  # noqa: E402

COLUMNS = ("scale from", "posed", "scale error %", "heading error deg",
           "position m as placed (median / max)", "rotation deg as placed (median / max)",
           "position m after similarity (median / max)", "inlier share", "fit s")


def colmap_project(photos: Path, work: Path) -> Path:
    """``work/colmap`` (sparse/0 and images/ linking to the photos), made by structure from
    motion unless it is there."""
    project = work / "colmap"
    if (project / "sparse" / "0").is_dir():
        return project
    with_db = work / "sfm-work"
    with_db.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    model = reconstruct(list_photos(photos), photos, with_db, SfmConfig())
    print(f"structure from motion: {model.num_reg_images()} photos, {model.num_points3D()} "
          f"points, {time.perf_counter() - start:.0f} s", file=sys.stderr)
    (project / "sparse" / "0").mkdir(parents=True)
    model.write(str(project / "sparse" / "0"))
    (project / "images").symlink_to(photos.resolve())
    shutil.rmtree(with_db)
    return project


def row(label: str, project: Path, out: Path, scale: ScaleHint,
        truth: dict[str, np.ndarray]) -> list[str]:
    """One table row: the photos source on ``project`` with ``scale``, against ``truth``
    (with a city model, the fit's other fits are printed on stderr)."""
    if out.exists():
        shutil.rmtree(out)
    start = time.perf_counter()
    write_scenes(read_photos(project, PhotosOptions(scale=scale, progress=False)), out,
                 overwrite=False, progress=False)
    seconds = time.perf_counter() - start
    scene = read_scene(out / project.name)
    names = [Path(f.file_path).name for f in scene.frames]
    posed = np.stack([f.world_from_camera for f in scene.frames])
    true = np.stack([truth[n] for n in names])
    errors = pose_errors(posed, true)
    after = f"{np.median(errors.position_m):.3f} / {errors.position_m.max():.3f}"
    record = scene.extra["photos"]
    if record["scale_source"] != "city_model":
        return [label, f"{len(names)} of {len(truth)}", f"{100 * errors.scale_error:.3f}",
                "-", "-", "-", after, "-", f"{record['seconds']['metric_frame']:.1f}"]
    fit = record["city_model"]
    print(f"{label}: best fit {fit['inliers']} points within {fit['inlier_distance_m']} m "
          f"({fit['on_building_share']:.0%} of them on the building itself), "
          f"{fit['best_within_judge']} within {fit['judge_m']} m; other fits (heading deg, "
          "scale, points within the same two):", file=sys.stderr)
    for other in fit["alternatives"]:
        print(f"  {other['heading_deg']:.2f} {other['scale_factor']:.4f} {other['inliers']} "
              f"{other['within_judge']}", file=sys.stderr)
    _, turn, _ = similarity_alignment(posed[:, :3, 3], true[:, :3, 3])
    heading = np.degrees(np.arctan2(turn[1, 0], turn[0, 0]))
    position = np.linalg.norm(posed[:, :3, 3] - true[:, :3, 3], axis=1)
    rotation = np.array([rotation_angle_deg(t[:3, :3].T @ p[:3, :3])
                         for p, t in zip(posed, true)])
    return [label, f"{len(names)} of {len(truth)}", f"{100 * errors.scale_error:.3f}",
            f"{heading:+.3f}", f"{np.median(position):.3f} / {position.max():.3f}",
            f"{np.median(rotation):.3f} / {rotation.max():.3f}", after,
            f"{fit['inlier_share']:.3f}",
            f"{record['seconds']['metric_frame']:.1f} (all: {seconds:.0f})"]


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--photos", type=Path, required=True, help="folder of stripped renders")
    p.add_argument("--truth", type=Path, required=True, help="the rendered scene")
    p.add_argument("--split", default="street", help="its frames the photos are (street)")
    p.add_argument("--city-model", type=Path, required=True, help="CityGML file or folder")
    p.add_argument("--city-building", help="the building's id in it")
    p.add_argument("--work", type=Path, required=True, help="COLMAP project and scenes")
    args = p.parse_args(argv)
    truth = stripped_poses(args.truth, [args.split])
    project = colmap_project(args.photos, args.work)
    rows = [row("city model", project, args.work / "city-model",
                ScaleHint(city_model=args.city_model, city_building=args.city_building),
                truth),
            row("known distance", project, args.work / "known-distance",
                ScaleHint(known_distance=known_pair(truth)), truth)]
    print(markdown_table(f"Scale, north and place of {args.photos.name} from a city model",
                         COLUMNS, rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
