"""2D-S and 2D-SS finding their own facades on views without facade ids; prints Markdown.

    python bench/own_facades.py --data /tmp/tiny            # train (orbit) views
    python bench/own_facades.py --data DIR --split street

Per method and building: facades found, truth facades, those covered (an estimate reached
them under the one scoring rule, :mod:`metrics.score.facade_scoring`), false positives, the mean
facade WWR error in points over covered facades, the building WWR error in points, the
building facade-area error (%) and the time per building. Report-only sets (heldout,
lod3) are refused: the settings are chosen here (:mod:`dataset.set_roles`).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

# Run as a script, this file's folder is sys.path[0]: put the repository root there instead.
sys.path[0] = str(Path(__file__).resolve().parent.parent)

import numpy as np  # noqa: E402

from baselines.wwr2ds import Wwr2dsConfig, run_2ds  # noqa: E402
from baselines.wwr2dss import Wwr2dssConfig, run_2dss  # noqa: E402
from dataset.set_roles import refuse_report_only  # noqa: E402
from envelope.method_input import method_input  # noqa: E402
from envelope.scenes.scene import find_scene_folders, read_scene  # noqa: E402
from metrics.score.errors import building_errors, facade_errors  # noqa: E402

RUNS = {"2D-SS": lambda s, split: run_2dss(s, split, Wwr2dssConfig()),
        "2D-S": lambda s, split: run_2ds(s, split, Wwr2dsConfig())}
HEADER = ("| method | building | found | truth | covered | false pos. | WWR pts (mean) | "
          "building WWR pts | facade area % | s |")


def bench_row(method: str, scene_dir: Path, split: str) -> dict:
    """One method on one scene's ``split``: the figures of the module docstring."""
    scene = read_scene(scene_dir)
    start = time.perf_counter()
    result = RUNS[method](method_input(scene), split)
    seconds = time.perf_counter() - start
    truth = scene.building
    rows = facade_errors(result, truth)
    points = [r.wwr_points for r in rows if r.kind == "matched" and r.wwr_points is not None]
    b = building_errors(result, truth)
    return {"method": method, "building": scene_dir.name, "found": len(result.facades),
            "truth": len(truth.facades),
            "covered": sum(r.kind == "matched" for r in rows),
            "false_positives": sum(r.kind == "false_positive" for r in rows),
            "wwr_points": float(np.mean(points)) if points else float("nan"),
            "building_wwr_points": 100 * abs(b.wwr_est - b.wwr_true),
            "facade_ape": b.facade_ape if b.facade_ape is not None else float("nan"),
            "seconds": seconds}


def markdown(rows: list[dict]) -> str:
    """The table of ``rows``, then one total line per method (sums, and means per building)."""
    lines = [HEADER, "|" + "---|" * (HEADER.count("|") - 1)]
    fmt = ("| {method} | {building} | {found} | {truth} | {covered} | {false_positives} | "
           "{wwr_points:.1f} | {building_wwr_points:.1f} | {facade_ape:.1f} | {seconds:.1f} |")
    lines += [fmt.format(**r) for r in rows]
    for method in dict.fromkeys(r["method"] for r in rows):
        mine = [r for r in rows if r["method"] == method]
        total = {k: sum(r[k] for r in mine) for k in ("found", "truth", "covered",
                                                       "false_positives")}
        means = {k: float(np.nanmean([r[k] for r in mine])) for k in (
            "wwr_points", "building_wwr_points", "facade_ape", "seconds")}
        lines.append(fmt.format(method=f"**{method}**", building=f"all {len(mine)}", **total,
                                **means))
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, required=True, help="a folder of scene folders")
    parser.add_argument("--split", default="train", help="views without facade ids")
    parser.add_argument("--methods", default=",".join(RUNS))
    args = parser.parse_args(argv)
    scenes = find_scene_folders(args.data, with_images=True)
    refuse_report_only(scenes, "bench/own_facades.py chooses the own-facade settings")
    rows = [bench_row(m, s, args.split) for m in args.methods.split(",") for s in scenes]
    print(markdown(rows))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
