"""Time ``metrics.export.command`` (every format) on a comparison's results; prints Markdown.

    python bench/export.py                       # the built-in default run's results
    python bench/export.py --results R --data D  # any comparison

Reads the results and truths once, then times :func:`metrics.export.command.export` with
every format ``--repeat`` times into a temporary folder (best and median wall
time, and the CPU time of this process), then each format alone once. The
issue's bound is 10 s for every format on the built-in default run.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path[0] = str(Path(__file__).resolve().parent.parent)

from dataset.benchmark_cache import DefaultBenchmark  # noqa: E402
from metrics.export.command import FORMATS, export, read_inputs  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    default = DefaultBenchmark().folder
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--results", type=Path, default=default.with_name(
        f"{default.name}-results"), help="result JSONs (default: the built-in default run's)")
    parser.add_argument("--data", type=Path, default=default,
                        help="scenes with building.json (default: the built-in benchmark)")
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args(argv)
    start = time.perf_counter()
    inputs = read_inputs(args.results, args.data)
    read_s = time.perf_counter() - start
    walls, cpus = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(args.repeat):
            t0, c0 = time.perf_counter(), time.process_time()
            written = export(inputs, Path(tmp) / f"all{i}", FORMATS)
            walls.append(time.perf_counter() - t0)
            cpus.append(time.process_time() - c0)
        each = {}
        for fmt in FORMATS:
            t0 = time.perf_counter()
            export(inputs, Path(tmp) / fmt, (fmt,))
            each[fmt] = time.perf_counter() - t0
    methods = sorted({(r.method, r.protocol) for r in inputs.results})
    print(f"results: {args.results} ({len(inputs.results)} results of "
          f"{len({r.scene for r in inputs.results})} buildings: "
          f"{', '.join(f'{m} {p}' for m, p in methods)}); reading them and the truths "
          f"{read_s:.2f} s\n")
    print("| what | wall s | CPU s |\n|---|---|---|")
    print(f"| every format ({len(written)} files), best of {args.repeat} | {min(walls):.3f} | "
          f"{min(cpus):.3f} |")
    print(f"| every format, median | {statistics.median(walls):.3f} | "
          f"{statistics.median(cpus):.3f} |")
    for fmt, seconds in each.items():
        print(f"| {fmt} alone | {seconds:.3f} | |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
