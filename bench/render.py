"""Renderer speed and memory (dataset.rendering.render, dataset.generate); prints the figures.

    python bench/render.py            # per-image times, one whole building, tiny preset x 2 workers
    python bench/render.py --full     # + the whole paper preset with 2 workers (long)

Per-image figures are single-process with BLAS/OpenMP pinned to one thread:
the median over 5 orbit views of each ``tiny`` building at 512 x 512, after one
warm-up render. "Whole building" runs :func:`dataset.scenes.scene_writer.generate_scene`
in this process (rendering plus PNG writing of all five modalities). The preset
runs go through the CLI in a subprocess with ``--workers 2``; their peak memory
is the largest sum of resident memory over the process tree, polled every 0.2 s.
Without ``--full`` the paper preset's wall time is extrapolated from the
measured frames per second and the paper preset's frame count (stated as such).
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from dataset.presets import build_building, preset_recipes  # noqa: E402
from dataset.rendering.facade_patches import facade_patches  # noqa: E402
from dataset.rendering.orbit_views import OrbitConfig, sample_orbit_views  # noqa: E402
from dataset.rendering.render import Raycaster, render_ground_truth, render_rgb, render_view  # noqa: E402
from dataset.scenes.scene_writer import GenerateConfig, generate_scene  # noqa: E402
from envelope.scenes.images import (  # noqa: E402
    write_depth_m,
    write_facade_ids,
    write_labels,
    write_normals,
    write_rgb,
)


def per_image(resolution: int) -> dict[str, float]:
    """Median seconds per image of each rendering step over the tiny buildings' views."""
    k = GenerateConfig(resolution=resolution).intrinsics()
    times: dict[str, list[float]] = {}

    def timed(name: str, fn, *args, **kwargs) -> None:
        t0 = time.perf_counter()
        fn(*args, **kwargs)
        times.setdefault(name, []).append(time.perf_counter() - t0)

    with tempfile.TemporaryDirectory() as tmp:
        for recipe in preset_recipes("tiny"):
            building = build_building(recipe)
            timed("BVH build (per building)", Raycaster, building.mesh)
            rc = Raycaster(building.mesh)
            poses = sample_orbit_views(building, rc, k, 5, config=OrbitConfig(), seed=0)
            render_rgb(rc, k, poses[0])  # warm-up
            for pose in poses:
                timed("ground truth (depth, normals, labels, ids)", render_ground_truth,
                      rc, k, pose)
                timed("RGB with shadows", render_rgb, rc, k, pose, seed=1)
                timed("RGB with shadows, 2x2 supersampling", render_rgb, rc, k, pose, seed=1,
                      supersampling=2)
                timed("ground truth + RGB (one cast)", render_view, rc, k, pose, seed=1)
                gt, rgb = render_view(rc, k, pose, seed=1)
                timed("writing the 5 PNGs", _write_frame, Path(tmp), gt, rgb)
    return {name: statistics.median(v) for name, v in times.items()}


def _write_frame(out: Path, gt, rgb) -> None:
    write_rgb(out / "r.png", rgb)
    write_depth_m(out / "d.png", gt.depth_z_m, 0.002)
    write_labels(out / "s.png", gt.labels)
    write_normals(out / "n.png", gt.normals_world)
    write_facade_ids(out / "i.png", gt.facade_ids)


def whole_building(views: int, resolution: int) -> tuple[int, float]:
    """(frames, seconds) to generate the tiny L-shaped building's scene in this process."""
    recipe = next(r for r in preset_recipes("tiny") if r.family == "l_shaped")
    building = build_building(recipe)
    config = GenerateConfig(resolution=resolution, views=views)
    with tempfile.TemporaryDirectory() as tmp, warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        t0 = time.perf_counter()
        root = generate_scene(building, tmp, config, seed=0, progress=False)
        seconds = time.perf_counter() - t0
        frames = len(list((root / "images").iterdir()))
    return frames, seconds


def preset_run(preset: str, views: int, resolution: int, workers: int) -> dict[str, float]:
    """Wall time, frames and peak resident memory (tree sum) of a CLI preset run."""
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [sys.executable, "-m", "dataset.generate", "--preset", preset, "--out", tmp,
               "--views", str(views), "--resolution", str(resolution),
               "--workers", str(workers), "--quiet"]
        t0 = time.perf_counter()
        proc = subprocess.Popen(cmd, cwd=ROOT, stdout=subprocess.DEVNULL,
                                stderr=subprocess.PIPE, text=True)
        peak_kb = 0
        while proc.poll() is None:
            peak_kb = max(peak_kb, _tree_rss_kb(proc.pid))
            time.sleep(0.2)
        wall = time.perf_counter() - t0
        if proc.returncode != 0:
            raise SystemExit(f"preset run failed: {proc.stderr.read().strip()[-500:]}")
        frames = sum(1 for _ in Path(tmp).glob("*/images/*.png"))
    return {"wall_s": wall, "frames": frames, "peak_rss_mb": peak_kb / 1024}


def paper_frame_count(views: int) -> int:
    """Frames the paper preset holds: orbit views plus 1 ideal + 5 multi per facade patch."""
    total = 0
    for recipe in preset_recipes("paper"):
        patches = facade_patches(build_building(recipe))
        total += views + 6 * len(patches)
    return total


def _tree_rss_kb(root_pid: int) -> int:
    """Summed VmRSS (kB) of a process and all its descendants (Linux /proc)."""
    parent: dict[int, int] = {}
    rss: dict[int, int] = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            status = (entry / "status").read_text()
        except OSError:
            continue
        fields = dict(line.split(":", 1) for line in status.splitlines() if ":" in line)
        parent[int(entry.name)] = int(fields.get("PPid", "0").strip())
        rss[int(entry.name)] = int(fields.get("VmRSS", "0 kB").split()[0])
    total, stack = 0, [root_pid]
    while stack:
        pid = stack.pop()
        total += rss.get(pid, 0)
        stack.extend(child for child, par in parent.items() if par == pid)
    return total


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--full", action="store_true", help="also run the whole paper preset")
    p.add_argument("--full-only", action="store_true",
                   help="run only the whole paper preset (after a quick run)")
    p.add_argument("--resolution", type=int, default=512)
    p.add_argument("--building-views", type=int, default=40,
                   help="orbit views of the whole-building run (default 40)")
    p.add_argument("--subset-views", type=int, default=40,
                   help="orbit views per building of the quick tiny-preset run (default 40)")
    args = p.parse_args()
    res = args.resolution
    print(f"load average at start: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    if args.full_only:
        full = preset_run("paper", GenerateConfig().views, res, workers=2)
        print(f"\nPreset paper, default config, 2 workers: {full['frames']} frames, wall "
              f"{full['wall_s'] / 60:.1f} min ({full['frames'] / full['wall_s']:.2f} frames/s), "
              f"peak memory {full['peak_rss_mb']:.0f} MB; load average at end "
              f"{os.getloadavg()[0]:.1f}")
        return 0

    print(f"\nPer image, {res}x{res}, one process (median over 15 views):")
    for name, seconds in per_image(res).items():
        print(f"  {name:<45} {seconds:7.3f} s")

    frames, seconds = whole_building(args.building_views, res)
    print(f"\nWhole building (tiny_l_shaped, {args.building_views} orbit views + facade views, "
          f"{res}px, one process): {frames} frames in {seconds:.1f} s = "
          f"{frames / seconds:.2f} frames/s (each frame: 5 PNGs)")

    sub = preset_run("tiny", args.subset_views, res, workers=2)
    rate = sub["frames"] / sub["wall_s"]
    print(f"\nPreset tiny, {args.subset_views} orbit views, {res}px, 2 workers: "
          f"{sub['frames']} frames, wall {sub['wall_s']:.1f} s ({rate:.2f} frames/s), "
          f"peak memory {sub['peak_rss_mb']:.0f} MB")

    paper_frames = paper_frame_count(GenerateConfig().views)
    if args.full:
        full = preset_run("paper", GenerateConfig().views, res, workers=2)
        print(f"\nPreset paper, default config, 2 workers: {full['frames']} frames, wall "
              f"{full['wall_s'] / 60:.1f} min ({full['frames'] / full['wall_s']:.2f} frames/s), "
              f"peak memory {full['peak_rss_mb']:.0f} MB")
    else:
        print(f"\nPreset paper, default config ({paper_frames} frames), 2 workers: "
              f"EXTRAPOLATED from the tiny run: {paper_frames / rate / 60:.0f} min "
              "(run with --full to measure)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
