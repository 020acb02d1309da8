"""The methods on the cameras structure from motion recovered, beside the true cameras;
prints Markdown tables.

    python bench/photos_methods.py --preset P --building B [--path orbit|street] [--context]
        [--views N] [--resolution PX] [--methods M,...] [--neural3d-steps S] --work DIR

Renders the building in the photo look (reused when ``DIR/scenes/B`` exists), poses the
capture's images alone with the photos source (``--known-distance`` from the true poses, as
``bench/photos_from_renders.py``; reused when posed before), writes the rendered scene twice
with the posed views only (:mod:`dataset.importers.photos.recovered_poses`: ``B`` on the
true cameras, ``B-sfm`` on the recovered ones, the same images and exact masks and depth)
and runs ``python -m metrics.compare`` on both, on the capture's protocol (``train`` for the
orbit, ``street``), where every method finds its own facades. Then per method: the building
WWR on each (points), their difference, the footprint IoU on each, and the matched facades'
WWR differences (the one scoring rule matches each scene's facades with the truth's).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench.tables import markdown_table  # noqa: E402
from dataset.generate import generate_preset  # noqa: E402
from dataset.importers.photos.recovered_poses import scenes_true_and_recovered  # noqa: E402
from dataset.importers.photos.stripped_renders import pose_stripped_renders  # noqa: E402
from dataset.rendering.shading import RgbConfig  # noqa: E402
from dataset.rendering.street_views import StreetConfig  # noqa: E402
from dataset.scenes.scene_writer import GenerateConfig  # noqa: E402
from envelope.protocols import EVAL_SPLIT, STREET_SPLIT, TRAIN_PROTOCOL  # noqa: E402
from envelope.scenes.scene import read_scene  # noqa: E402
from metrics.report.tables import read_csv_rows  # noqa: E402

RECOVERED_SUFFIX = "-sfm"
COLUMNS = ("building", "method", "protocol", "views", "WWR true cameras %",
           "WWR recovered %", "difference points", "WWR error true / recovered %",
           "IoU true", "IoU recovered", "IoU difference", "facades matched (both)",
           "facade WWR difference points (median / max)")


def prepare(preset: str, building: str, path: str, args: argparse.Namespace) -> Path:
    """Render, pose and write the two scenes of one building into ``work/benchmark``."""
    work = args.work
    scene_dir = work / "scenes" / building
    if not (scene_dir / "transforms.json").is_file():
        config = GenerateConfig(resolution=args.resolution, views=args.views, ideal=False,
                                multi=False, context=args.context,
                                street=StreetConfig() if path == "street" else None,
                                rgb=RgbConfig(look="photo"))
        start = time.perf_counter()
        scene_dir, = generate_preset(preset, work / "scenes", config, buildings=[building],
                                     progress=False)
        print(f"{building}: rendered in {time.perf_counter() - start:.0f} s", file=sys.stderr)
    posed_dir = work / f"{building}-{path}" / "posed" / building
    if not (posed_dir / "transforms.json").is_file():
        splits = (STREET_SPLIT,) if path == "street" else (TRAIN_PROTOCOL, EVAL_SPLIT)
        run = pose_stripped_renders(scene_dir, work / f"{building}-{path}", splits)
        if run.errors is None:
            raise SystemExit(f"{building} {path}: {run.failure}")
        print(f"{building}: {run.posed} of {run.views} posed in {run.seconds:.0f} s, scale "
              f"error {100 * run.errors.scale_error:.3f} %", file=sys.stderr)
    benchmark = work / "benchmark"
    scenes_true_and_recovered(scene_dir, posed_dir, benchmark / building,
                              benchmark / f"{building}{RECOVERED_SUFFIX}")
    return benchmark


def rows_of(compare: Path, benchmark: Path, buildings: list[str],
            protocol: str) -> list[list[str]]:
    """One row per building and method from the comparison's per-building and per-facade
    CSV files (``benchmark``: the scenes, for their view counts)."""
    buildings_csv = read_csv_rows((compare / "per_building.csv").read_text())
    runs = {(r["scene"], r["method"]): r for r in buildings_csv if r["protocol"] == protocol}
    facades: dict[tuple[str, str, str], float] = {
        (r["scene"], r["method"], r["facade_id"]): float(r["wwr_est"])
        for r in read_csv_rows((compare / "per_facade.csv").read_text())
        if r["protocol"] == protocol and r["kind"] == "matched"}
    methods = sorted({m for _, m in runs})
    rows = []
    for building in buildings:
        sfm = f"{building}{RECOVERED_SUFFIX}"
        for method in methods:
            a, b = runs.get((building, method)), runs.get((sfm, method))
            if a is None or b is None or "ok" not in (a["status"], b["status"]):
                continue
            shared = [fid for (s, m, fid) in facades if s == building and m == method
                      and (sfm, method, fid) in facades]
            diffs = np.array([100 * abs(facades[(sfm, method, f)] - facades[(building, method,
                                                                                f)])
                              for f in shared])
            views = len(read_scene(benchmark / building).frames_in(protocol))
            rows.append([building, method, protocol, str(views),
                         _pct(a["wwr_est"]), _pct(b["wwr_est"]),
                         f"{100 * (float(b['wwr_est']) - float(a['wwr_est'])):+.2f}",
                         f"{float(a['wwr_ape']):.2f} / {float(b['wwr_ape']):.2f}",
                         *_iou(a["footprint_iou"], b["footprint_iou"]), str(len(shared)),
                         f"{np.median(diffs):.2f} / {diffs.max():.2f}" if len(diffs) else "-"])
    return rows


def _pct(value: str) -> str:
    return f"{100 * float(value):.2f}"


def _iou(a: str, b: str) -> list[str]:
    if not a or not b:
        return ["-", "-", "-"]
    return [f"{float(a):.3f}", f"{float(b):.3f}", f"{float(b) - float(a):+.3f}"]


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--preset", required=True, help="the building's preset (e.g. tiny, lod3)")
    p.add_argument("--building", required=True, action="append",
                   help="a building of that preset (repeat for more)")
    p.add_argument("--path", choices=("orbit", "street"), default="orbit",
                   help="the capture to pose and measure on (default: orbit)")
    p.add_argument("--context", action="store_true", help="render the neighbours too")
    p.add_argument("--views", type=int, default=48, help="orbit views (default 48)")
    p.add_argument("--resolution", type=int, default=1024, help="image size (default 1024)")
    p.add_argument("--methods", default="2D-S,2D-SS,neural3d")
    p.add_argument("--neural3d-steps", type=int, default=2000)
    p.add_argument("--neural3d-resolution", type=int, default=128)
    p.add_argument("--neural3d-threads", type=int, default=1,
                   help="torch threads per training (default 1: the cores are shared)")
    p.add_argument("--work", type=Path, required=True,
                   help="renders, posed photos, scenes and results stay here")
    args = p.parse_args(argv)
    for building in args.building:
        benchmark = prepare(args.preset, building, args.path, args)
    protocol = STREET_SPLIT if args.path == "street" else TRAIN_PROTOCOL
    compare = args.work / "compare"
    command = [sys.executable, "-m", "metrics.compare", "--data", str(benchmark),
               "--methods", args.methods, "--views", protocol,
               "--results", str(args.work / "results"), "--out", str(compare),
               "--neural3d-steps", str(args.neural3d_steps),
               "--neural3d-resolution", str(args.neural3d_resolution),
               "--neural3d-threads", str(args.neural3d_threads)]
    print("$ " + " ".join(command), file=sys.stderr)
    subprocess.run(command, check=True, cwd=Path(__file__).resolve().parents[1])
    print(markdown_table("The methods on true and on recovered cameras (same images, exact "
                         "masks and depth)", COLUMNS, rows_of(compare, benchmark,
                                                              args.building, protocol)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
