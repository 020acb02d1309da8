"""Speed and accuracy of the 2D baselines (2D-S, 2D-SS); prints Markdown.

    python bench/baselines.py            # the tiny preset, generated at 512² in a temp dir
    python bench/baselines.py --data /work/data/paper --out docs/baselines_bench.md

Speed: views per second of each method on the ideal and multi views of the
512 x 512 scenes, two ways: "compute" times the method on views already in
memory (best of ``--repeat`` passes); "end to end" times ``run_2ds`` /
``run_2dss`` per scene and protocol, PNG reading and result assembly included.
Each is given per wall-clock second and per CPU second of this process (all
its threads): on a machine shared with other jobs the CPU figure is the one
that does not depend on the neighbours. ``--threads`` sets torch's threads.
Scenes of another resolution are skipped for speed (a tiny preset at 512² is
generated instead).

Accuracy: both methods on both protocols on every scene of ``--data``; the
absolute percentage errors of WWR, window area and facade area against
``building.json``, mean ± std per building family (metrics.score.errors / aggregate).
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
import warnings
from pathlib import Path

# Run as a script, this file's folder is sys.path[0] and its name would shadow
# the ``baselines`` package: put the repository root there instead.
sys.path[0] = str(Path(__file__).resolve().parent.parent)

import numpy as np  # noqa: E402
import torch  # noqa: E402

from baselines.views import load_views  # noqa: E402
from baselines.wwr2ds import Wwr2dsConfig, measure_view_2ds, run_2ds  # noqa: E402
from baselines.wwr2dss import (  # noqa: E402
    Wwr2dssConfig,
    measure_view_geometry,
    rectify_views,
    run_2dss,
)
from envelope.atomic import write_text_atomic  # noqa: E402
from envelope.method_input import MethodInput  # noqa: E402
from envelope.protocols import VIEW_PROTOCOLS  # noqa: E402
from envelope.scenes.scene import (  # noqa: E402
    find_scene_folders,  # noqa: E402
    read_method_input,
    read_scene,
)
from metrics.report.report import table2_errors  # noqa: E402
from metrics.report.tables import to_markdown  # noqa: E402
from metrics.score.aggregate import aggregate_by_family  # noqa: E402
from metrics.score.errors import building_errors, failed_building  # noqa: E402

SPEED_SIZE = 512
PROTOCOLS = VIEW_PROTOCOLS


def speed_section(scenes: list[MethodInput], repeat: int) -> str:
    """Markdown lines with views/s of both methods (compute only, and end to end)."""
    views_2ds = [v for s in scenes for p in PROTOCOLS
                 for v in load_views(s, p, depth="optional").views]
    views_2dss = [v for s in scenes for p in PROTOCOLS
                  for v in load_views(s, p, depth="required").views]
    c2ds, c2dss = Wwr2dsConfig(), Wwr2dssConfig()

    def run_2ds_views() -> None:
        for v in views_2ds:
            try:
                measure_view_2ds(v, c2ds)
            except ValueError:
                pass

    def run_2dss_views() -> None:
        geoms = []
        for n, v in enumerate(views_2dss):
            try:
                geoms.append(measure_view_geometry(v, c2dss, np.random.default_rng(n)))
            except ValueError:
                pass
        rectify_views(geoms, c2dss)

    def run_scenes(run) -> None:
        for s in scenes:
            for p in PROTOCOLS:
                run(s, p)

    n1, n2 = len(views_2ds), len(views_2dss)
    lines = [
        f"Speed at {SPEED_SIZE}², {len(scenes)} scenes, {n1} views, torch threads "
        f"{torch.get_num_threads()}, {os.cpu_count()} cores, load average "
        f"{os.getloadavg()[0]:.1f} (views/s per wall second / per CPU second):",
        "",
        "| method | compute, wall | compute, CPU | end to end, wall | end to end, CPU |",
        "|---|---|---|---|---|",
    ]
    for name, n, fn, run in (("2D-S", n1, run_2ds_views, run_2ds),
                             ("2D-SS", n2, run_2dss_views, run_2dss)):
        wall, cpu = _best_of(fn, repeat)
        e2e_wall, e2e_cpu = _best_of(lambda run=run: run_scenes(run), 1)
        lines.append(f"| {name} | {n / wall:.0f} | {n / cpu:.0f} | {n / e2e_wall:.0f} | "
                     f"{n / e2e_cpu:.0f} |")
    return "\n".join([*lines, ""])


def error_section(folders: list[Path]) -> str:
    """Markdown Table 2 (APE mean ± std per family) for both methods and protocols."""
    rows = []
    for folder in folders:
        truth = read_scene(folder).building
        scene = read_method_input(folder)
        for method, run in (("2D-S", run_2ds), ("2D-SS", run_2dss)):
            for p in PROTOCOLS:
                try:
                    rows.append(building_errors(run(scene, p), truth))
                except ValueError as exc:
                    family = truth.type if truth is not None else "unknown"
                    rows.append(failed_building(folder.name, family, method, p, str(exc)))
    return to_markdown(table2_errors(aggregate_by_family(rows)),
                       comment="bench/baselines.py")


def _best_of(fn, repeat: int) -> tuple[float, float]:
    """Least wall-clock and least CPU seconds of ``repeat`` calls after a warm-up."""
    fn()  # warm-up (imports, allocations)
    wall, cpu = [], []
    for _ in range(repeat):
        w0, c0 = time.perf_counter(), time.process_time()
        fn()
        wall.append(time.perf_counter() - w0)
        cpu.append(time.process_time() - c0)
    return min(wall), min(cpu)


def _scenes_at(folders: list[Path], size: int) -> list[MethodInput]:
    scenes = [read_method_input(f) for f in folders]
    return [s for s in scenes
            if s.frames and (s.frames[0].intrinsics.width, s.frames[0].intrinsics.height)
            == (size, size)]


def _tiny_preset(root: Path) -> list[Path]:
    from dataset.generate import GenerateConfig, generate_preset

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        generate_preset("tiny", root, GenerateConfig(resolution=SPEED_SIZE, views=4),
                        progress=False)
    return find_scene_folders(root, with_images=True)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", type=Path, default=None,
                        help="folder of scene folders (default: tiny preset at 512², generated)")
    parser.add_argument("--out", type=Path, default=None, help="also write the Markdown here")
    parser.add_argument("--repeat", type=int, default=3, help="timed passes (best is kept)")
    parser.add_argument("--threads", type=int, default=None,
                        help="torch threads (default: torch's own choice)")
    args = parser.parse_args(argv)
    if args.threads:
        torch.set_num_threads(args.threads)
    with tempfile.TemporaryDirectory(prefix="bench_baselines_") as tmp:
        try:
            folders = (find_scene_folders(args.data, with_images=True) if args.data
                       else _tiny_preset(Path(tmp)))
            speed_scenes = _scenes_at(folders, SPEED_SIZE)
            if not speed_scenes:
                speed_scenes = _scenes_at(_tiny_preset(Path(tmp) / "tiny512"), SPEED_SIZE)
        except ValueError as exc:
            print(f"bench/baselines.py: error: {exc}", file=sys.stderr)
            return 2
        text = "\n".join([
            f"# 2D baselines on {args.data or 'the tiny preset'}",
            "",
            speed_section(speed_scenes, args.repeat),
            error_section(folders),
        ])
    print(text)
    if args.out:
        write_text_atomic(args.out, text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
