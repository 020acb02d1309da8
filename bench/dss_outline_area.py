"""2D-SS facade area from L x H against the mask outline (gables, steps), before and after.

    python bench/dss_outline_area.py --data /tmp/realistic --views ideal,multi

Runs 2D-SS on every scene of ``--data`` twice: with ``min_rectangle_fill=0`` (facade
area always L x H, as before) and with the default (the mask outline's area where it
fills less of the rectangle). Prints per building and protocol the absolute percentage
errors of facade area, window area and WWR (metrics.score.errors), then their means.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path

# Run as a script, this file's folder is sys.path[0] and its name would shadow
# the ``baselines`` package: put the repository root there instead.
sys.path[0] = str(Path(__file__).resolve().parent.parent)

import numpy as np  # noqa: E402

from baselines.wwr2dss import Wwr2dssConfig, run_2dss  # noqa: E402
from dataset.set_roles import refuse_report_only  # noqa: E402
from envelope.scenes.scene import (  # noqa: E402
    find_scene_folders,  # noqa: E402
    read_method_input,
    read_scene,
)
from metrics.score.errors import building_errors  # noqa: E402


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--data", type=Path, required=True)
    p.add_argument("--views", default="ideal,multi")
    args = p.parse_args()
    try:
        refuse_report_only(find_scene_folders(args.data, with_images=True),
                           "choose 2D-SS's facade-area rule")
    except ValueError as exc:
        p.error(str(exc))
    configs = {"L x H": replace(Wwr2dssConfig(), min_rectangle_fill=0.0),
               "outline": Wwr2dssConfig()}
    totals: dict[tuple[str, str], list[tuple[float, float, float]]] = {}
    print(f"{'scene':22s} {'views':6s} {'variant':8s} facade% window%   WWR%")
    for folder in find_scene_folders(args.data, with_images=True):
        truth, scene = read_scene(folder).building, read_method_input(folder)
        for protocol in args.views.split(","):
            for name, config in configs.items():
                e = building_errors(run_2dss(scene, protocol, config), truth)
                row = (e.facade_ape, e.window_ape, e.wwr_ape)
                totals.setdefault((protocol, name), []).append(row)
                print(f"{folder.name:22s} {protocol:6s} {name:8s} "
                      + " ".join(f"{x:7.2f}" for x in row))
    for (protocol, name), rows in totals.items():
        mean = np.mean(np.array(rows, dtype=float), axis=0)
        print(f"mean {protocol:6s} {name:8s} " + " ".join(f"{x:7.2f}" for x in mean))


if __name__ == "__main__":
    main()
