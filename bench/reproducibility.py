"""Two clean runs of ``python -m metrics.compare`` write byte-identical tables.

    python bench/reproducibility.py                      # the built-in default, twice
    python bench/reproducibility.py -- --data data/tiny --methods 2D-S,2D-SS

Each run starts in its own empty working folder (so the built-in default's
benchmark cache, results and tables are made from scratch), with the same
command line. Prints the SHA-256 of every table CSV of both runs, whether they
match, and each run's wall time (which is allowed to differ: it is kept in
``timing.csv``, the one file not compared). Exit code 1 if any table differs.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

TABLES = ("table2_errors.csv", "table3_footprint_iou.csv", "per_building.csv",
          "per_facade.csv")


def run_once(folder: Path, compare_args: list[str]) -> tuple[dict[str, str], float]:
    """Run the comparison in ``folder``; return {table: sha256} and the wall time (s)."""
    root = Path(__file__).resolve().parent.parent
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        [str(root), *filter(None, [os.environ.get("PYTHONPATH")])])}
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "metrics.compare", *compare_args, "--out", "out",
                    "--results", "results"], cwd=folder, env=env, check=True)
    wall = time.perf_counter() - start
    hashes = {}
    for name in TABLES:
        path = folder / "out" / name
        hashes[name] = hashlib.sha256(path.read_bytes()).hexdigest() if path.is_file() else "-"
    return hashes, wall


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("compare_args", nargs="*",
                   help="arguments for metrics.compare after `--` (default: none, the "
                   "built-in default); --out and --results are set per run")
    args = p.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="envelope-bench-repro-") as tmp:
        runs = []
        for name in ("first", "second"):
            folder = Path(tmp) / name
            folder.mkdir()
            runs.append(run_once(folder, args.compare_args))
    (first, wall1), (second, wall2) = runs
    print("| table | first run SHA-256 | second run SHA-256 | same |\n|---|---|---|---|")
    for name in TABLES:
        print(f"| {name} | {first[name][:16]} | {second[name][:16]} | "
              f"{'yes' if first[name] == second[name] else 'NO'} |")
    print(f"\nwall time: {wall1:.0f} s and {wall2:.0f} s")
    return 0 if first == second else 1


if __name__ == "__main__":
    sys.exit(main())
