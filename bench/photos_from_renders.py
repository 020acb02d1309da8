"""Structure from motion on renders stripped of their poses; prints a Markdown table.

    python bench/photos_from_renders.py [--preset P --building B ...] [--views N]
        [--resolution PX] [--look photo|plain] [--paths orbit street] [--context]
        [--work DIR] [--shuffle SEED] [--exhaustive]

Renders each building (``--preset``/``--building`` pairs in order; default the tiny preset's
``tiny_l_shaped``) with ``--views`` orbit views and, with ``--paths ... street``, its street
frames (``--context``: with the neighbours the source gives, as ``dataset.generate
--context``) in the chosen look, copies only the RGB images into a folder of photos (JPEG
with the EXIF a camera writes, :mod:`dataset.importers.photos.stripped_renders`), runs the
photos source on them with ``--known-distance`` between the first photo and the one
farthest from it (the distance taken from the true poses: what a user pacing it would give),
and compares the recovered cameras with the true ones after the best similarity: share of
views posed, rotation error (deg), camera position error (m), scale error (%), the up axis's
tilt (deg).
Orbit (train + eval frames) and street frames are posed separately (different lenses).
``--shuffle SEED`` names the photos ``IMG_<n>.jpg`` in a random order drawn from the seed (a
user's unordered folder; :func:`~dataset.importers.photos.stripped_renders.strip_renders`);
``--exhaustive`` matches every pair of photos instead of the pairs preemptive matching keeps
(:class:`~dataset.importers.photos.sfm.SfmConfig`'s default).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench.tables import markdown_table  # noqa: E402
from dataset.generate import generate_preset  # noqa: E402
from dataset.importers.photos.preemptive_pairs import ExhaustiveMatching  # noqa: E402
from dataset.importers.photos.sfm import SfmConfig  # noqa: E402
from dataset.importers.photos.stripped_renders import pose_stripped_renders  # noqa: E402
from dataset.rendering.shading import RgbConfig  # noqa: E402
from dataset.rendering.street_views import StreetConfig  # noqa: E402
from dataset.scenes.scene_writer import GenerateConfig  # noqa: E402
from envelope.protocols import EVAL_SPLIT, STREET_SPLIT, TRAIN_PROTOCOL  # noqa: E402

COLUMNS = ("building", "path", "context", "look", "views", "posed", "rotation deg (median / max)",
           "position m (median / max)", "scale error %", "up deg", "SfM s")


def run_row(scene_dir: Path, work: Path, path: str, context: bool, look: str,
            sfm: SfmConfig, shuffle_seed: int | None = None) -> list[str]:
    splits = (STREET_SPLIT,) if path == "street" else (TRAIN_PROTOCOL, EVAL_SPLIT)
    run = pose_stripped_renders(scene_dir, work / f"{scene_dir.name}-{path}", splits, sfm=sfm,
                                shuffle_seed=shuffle_seed)
    head = [scene_dir.name, path, "yes" if context else "no", look, str(run.views),
            f"{run.posed} ({100 * run.posed_fraction:.0f} %)"]
    e = run.errors
    if e is None:
        print(f"{scene_dir.name} {path}: {run.failure}", file=sys.stderr)
        return head + ["-", "-", "-", "-", f"{run.seconds:.0f}"]
    return head + [f"{np.median(e.rotation_deg):.3f} / {e.rotation_deg.max():.3f}",
                   f"{np.median(e.position_m):.3f} / {e.position_m.max():.3f}",
                   f"{100 * e.scale_error:.2f}", f"{e.up_deg:.2f}", f"{run.seconds:.0f}"]


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--preset", action="append", help="preset of each --building")
    p.add_argument("--building", action="append", help="building of that preset")
    p.add_argument("--views", type=int, default=40, help="orbit views (default 40)")
    p.add_argument("--resolution", type=int, default=1024, help="image size (default 1024)")
    p.add_argument("--look", choices=("photo", "plain"), default="photo")
    p.add_argument("--paths", nargs="+", choices=("orbit", "street"), default=["orbit"],
                   help="captures to pose, each on its own (default: orbit)")
    p.add_argument("--context", action="store_true", help="render the neighbours too")
    p.add_argument("--work", type=Path, help="keep renders and models here (default: a "
                   "temporary folder)")
    p.add_argument("--shuffle", type=int, metavar="SEED", help="name the photos in a random "
                   "order drawn from SEED (default: by frame)")
    p.add_argument("--exhaustive", action="store_true", help="match every pair (default: "
                   "preemptive matching)")
    args = p.parse_args(argv)
    presets, buildings = args.preset or ["tiny"], args.building or ["tiny_l_shaped"]
    if len(presets) != len(buildings):
        p.error("give one --preset per --building")
    config = GenerateConfig(resolution=args.resolution, views=args.views, ideal=False,
                            multi=False, context=args.context,
                            street=StreetConfig() if "street" in args.paths else None,
                            rgb=RgbConfig(look=args.look))
    sfm = SfmConfig(matching=ExhaustiveMatching()) if args.exhaustive else SfmConfig()
    rows = []
    with tempfile.TemporaryDirectory(prefix="photos-from-renders-") as tmp:
        work = args.work or Path(tmp)
        for preset, building in zip(presets, buildings):
            start = time.perf_counter()
            scene_dir, = generate_preset(preset, work / "scenes", config, buildings=[building],
                                         progress=False)
            print(f"{building}: rendered in {time.perf_counter() - start:.0f} s",
                  file=sys.stderr)
            for path in args.paths:
                rows.append(run_row(scene_dir, work, path, args.context, args.look, sfm,
                                    args.shuffle))
    print(markdown_table(f"Photos source on stripped renders ({args.resolution} px)",
                         COLUMNS, rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
