"""Buildings per hour: neural3d on a benchmark one building after the other, and several at once.

    python bench/neural3d_throughput.py --data DIR [--steps 2000] [--resolution 128]
        [--jobs 2] [--device cpu|cuda] [--out DIR]

Runs the same comparison twice from scratch (fresh results folders), as a user would:

- ``one after the other``: ``python -m metrics.compare --data DIR --methods neural3d
  --executor local`` with ``--neural3d-threads JOBS`` on CPU (every core on one building),
  or the one GPU process on CUDA;
- ``JOBS at once``: the same with ``--executor processes``: ``--neural3d-threads 1 --cpus
  JOBS`` on CPU (one core a building), ``--neural3d-runs-per-gpu JOBS`` on CUDA.

Prints (Markdown) per arm the wall time of the whole command, seconds per building,
buildings per hour, the ratio to the first arm, and the accuracy the arm's results give
(mean WWR error and footprint IoU over the buildings, from the comparison's
``per_building.csv``), so a speed-up is read beside what it costs: the two arms train
with other thread counts, so their results differ by about a seed's spread. The
machine should be otherwise idle; nothing else is timed.
"""

from __future__ import annotations

import argparse
import csv
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class Arm:
    """One way to run the comparison: its name and its executor options."""

    name: str
    options: tuple[str, ...]


@dataclass(frozen=True)
class ArmFigures:
    """What one arm gave: wall seconds, buildings measured, mean WWR error (%) and IoU."""

    wall_s: float
    buildings: int
    wwr_ape_mean: float
    iou_mean: float


def arms(jobs: int, device: str) -> tuple[Arm, Arm]:
    """The two arms for ``jobs`` buildings at once on ``device``."""
    if device.startswith("cuda"):
        return (Arm("one after the other", ("--executor", "local")),
                Arm(f"{jobs} at once", ("--executor", "processes",
                                        "--neural3d-runs-per-gpu", str(jobs))))
    return (Arm("one after the other", ("--executor", "local", "--neural3d-threads", str(jobs))),
            Arm(f"{jobs} at once", ("--executor", "processes", "--neural3d-threads", "1",
                                    "--cpus", str(jobs))))


def run_arm(arm: Arm, data: Path, out: Path, *, steps: int, resolution: int,
            device: str) -> ArmFigures:
    """Run one arm's comparison into ``out`` and read its figures."""
    command = [sys.executable, "-m", "metrics.compare", "--data", str(data),
               "--methods", "neural3d", "--neural3d-steps", str(steps),
               "--neural3d-resolution", str(resolution), "--device", device,
               "--results", str(out / "results"), "--out", str(out / "compare"), *arm.options]
    print(f"[{arm.name}] {' '.join(command[1:])}", file=sys.stderr, flush=True)
    tic = time.perf_counter()
    done = subprocess.run(command, stdout=subprocess.DEVNULL)
    wall_s = time.perf_counter() - tic
    if done.returncode != 0:
        raise SystemExit(f"error: the {arm.name} comparison exited with {done.returncode}")
    return read_figures(out / "compare" / "per_building.csv", wall_s)


def read_figures(per_building: Path, wall_s: float) -> ArmFigures:
    """Mean WWR error and footprint IoU of the measured buildings of a ``per_building.csv``."""
    with per_building.open(newline="") as f:
        rows = [r for r in csv.DictReader(line for line in f if not line.startswith("#"))
                if r["status"] == "ok"]
    if not rows:
        raise SystemExit(f"error: {per_building} holds no measured building")
    wwr = [float(r["wwr_ape"]) for r in rows]
    iou = [float(r["footprint_iou"]) for r in rows]
    return ArmFigures(wall_s, len(rows), sum(wwr) / len(wwr), sum(iou) / len(iou))


def table(results: list[tuple[Arm, ArmFigures]]) -> str:
    """The Markdown table of the arms, the ratio taken to the first."""
    first = results[0][1]
    lines = ["| arm | buildings | wall s | s per building | buildings per hour | speed-up "
             "| WWR error % (mean) | footprint IoU (mean) |",
             "|---|---|---|---|---|---|---|---|"]
    for arm, f in results:
        per = f.wall_s / f.buildings
        lines.append(f"| {arm.name} | {f.buildings} | {f.wall_s:.0f} | {per:.0f} | "
                     f"{3600 / per:.1f} | {first.wall_s / f.wall_s:.2f}x | "
                     f"{f.wwr_ape_mean:.2f} | {f.iou_mean:.3f} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--data", type=Path, required=True,
                        help="a folder of scene folders (e.g. the tiny benchmark)")
    parser.add_argument("--steps", type=int, default=2000, help="training steps (default 2000)")
    parser.add_argument("--resolution", type=int, default=128,
                        help="marching-cubes resolution (default 128)")
    parser.add_argument("--jobs", type=int, default=2,
                        help="buildings at once in the second arm, and the cores of the first "
                        "on CPU (default 2)")
    parser.add_argument("--device", default="cpu", help="cpu (default) or cuda")
    parser.add_argument("--out", type=Path,
                        help="folder for both arms' results (default: a temporary one)")
    args = parser.parse_args(argv)
    if args.jobs < 1:
        parser.error("--jobs must be >= 1")
    with tempfile.TemporaryDirectory(prefix="throughput-") as tmp:
        out = args.out or Path(tmp)
        results = []
        for k, arm in enumerate(arms(args.jobs, args.device)):
            figures = run_arm(arm, args.data, out / f"arm{k}", steps=args.steps,
                              resolution=args.resolution, device=args.device)
            results.append((arm, figures))
        print(table(results))
    return 0


if __name__ == "__main__":
    sys.exit(main())
