"""neural3d's figures at every check of a comparison's runs: time-to-target and late stability.

    python bench/neural3d_checks.py --results DIR [--resolution 256] [--last N]
        [--scenes NAME ...] [--json FILE] [--plot FILE.png] [--threads 2]

Reads the run folders a comparison kept (``DIR/neural3d_runs/<scene>/``, DIR
being ``metrics.compare``'s ``--results``), measures the snapshot of every
evaluation step (``snapshots/step_<N>.pt``, or only the last ``--last N``) with
the extraction the comparison uses (``neural3d.extract.measure_field``,
marching cubes at ``--resolution``) and scores it against the scene's truth.
The training seconds at each check come from the run's ``eval.json``.

Prints, in Markdown: per building the checks and the spread (max - min) of the
WWR error and the footprint IoU over the last three checks; per family the
mean WWR error and IoU at each check step (the time-to-target curve, with the
mean training minutes), and how many buildings met the targets (WWR error
<= 5 %, IoU >= 0.96) at each step. ``--plot`` draws the curves.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

# Run as a script, this file's folder is sys.path[0]: put the repository root there instead.
sys.path[0] = str(Path(__file__).resolve().parent.parent)

import torch  # noqa: E402

from bench.neural3d import (  # noqa: E402  the targets and the spread, defined once
    IOU_TARGET,
    WWR_TARGET_PCT,
    last_checks_spread,
    on_target,
)
from bench.tables import markdown_table  # noqa: E402
from dataset.set_roles import refuse_report_only  # noqa: E402
from envelope.atomic import write_json_atomic  # noqa: E402
from envelope.results import code_version  # noqa: E402
from envelope.scenes.scene import read_scene  # noqa: E402
from metrics.score.errors import building_errors  # noqa: E402
from neural3d.extract import measure_field  # noqa: E402
from neural3d.extraction.extract_config import ExtractConfig  # noqa: E402
from neural3d.field.checkpoint import snapshot_steps  # noqa: E402
from neural3d.field.trained import load_trained_field  # noqa: E402
from neural3d.method import RUNS_FOLDER, trained_scene_dirs  # noqa: E402
from neural3d.training.run_folder import read_evals  # noqa: E402


def run_checks(run_dir: Path, extract: ExtractConfig, last: int | None) -> dict:
    """One building: a row per measured snapshot (step, training s, errors, measuring s)."""
    run = json.loads((run_dir / "run.json").read_text())
    scene = read_scene(run["scene_dir"], validate=False)
    train_s = {int(e["step"]): float(e["train_s"]) for e in read_evals(run_dir)}
    steps = snapshot_steps(run_dir)
    rows = []
    for step in steps[-last:] if last else steps:
        tic = time.perf_counter()
        field = load_trained_field(run_dir, device=torch.device("cpu"), step=step)
        result, _ = measure_field(field, extract)
        errors = building_errors(result, scene.building)
        rows.append({"step": step, "train_s": train_s.get(step), "wwr_ape": errors.wwr_ape,
                     "window_ape": errors.window_ape, "facade_ape": errors.facade_ape,
                     "footprint_iou": errors.footprint_iou,
                     "measure_s": round(time.perf_counter() - tic, 1)})
        print(f"  {run_dir.name} step {step}: {rows[-1]}", file=sys.stderr, flush=True)
    return {"scene": run_dir.name, "family": scene.building.type if scene.building else None,
            "checks": rows, "last3_spread": last_checks_spread(rows)}


def family_curves(buildings: list[dict]) -> dict[str, list[dict]]:
    """Per family and check step: mean WWR error, mean IoU, mean training minutes, on target."""
    curves: dict[str, list[dict]] = {}
    for family in sorted({b["family"] for b in buildings}, key=str):
        members = [b for b in buildings if b["family"] == family]
        steps = sorted({r["step"] for b in members for r in b["checks"]})
        curve = []
        for step in steps:
            rows = [r for b in members for r in b["checks"] if r["step"] == step]
            curve.append({
                "step": step, "buildings": len(rows),
                "train_min": _mean([r["train_s"] / 60 for r in rows if r["train_s"] is not None]),
                "wwr_ape": _mean([r["wwr_ape"] for r in rows if r["wwr_ape"] is not None]),
                "footprint_iou": _mean([r["footprint_iou"] for r in rows
                                        if r["footprint_iou"] is not None]),
                "on_target": sum(on_target(r) for r in rows)})
        curves[str(family)] = curve
    return curves


def _mean(values: list[float]) -> float | None:
    return statistics.fmean(values) if values else None


def _fmt(value: float | None, digits: int) -> str:
    return "n/a" if value is None else f"{value:.{digits}f}"


def markdown(buildings: list[dict], curves: dict[str, list[dict]]) -> str:
    per_building = []
    for b in buildings:
        final = b["checks"][-1] if b["checks"] else {}
        sp = b["last3_spread"]
        per_building.append([
            b["scene"], b["family"], ",".join(str(r["step"]) for r in b["checks"]),
            _fmt(final.get("wwr_ape"), 2), _fmt(final.get("footprint_iou"), 3),
            _fmt(sp["wwr_ape"], 2), _fmt(sp["footprint_iou"], 3)])
    per_check = [[family, c["step"], _fmt(c["train_min"], 1), _fmt(c["wwr_ape"], 2),
                  _fmt(c["footprint_iou"], 3), f"{c['on_target']}/{c['buildings']}"]
                 for family, curve in curves.items() for c in curve]
    return "\n\n".join([
        markdown_table("Per building: the last check, and the spread of the last three",
                       ["building", "family", "steps checked", "final WWR error %",
                        "final IoU", "WWR spread, last 3 (pts)", "IoU spread, last 3"],
                       per_building),
        markdown_table("Per family and check", ["family", "step", "mean training min",
                                                "mean WWR error %", "mean IoU", "on target"],
                       per_check)])


def plot(curves: dict[str, list[dict]], path: Path, title: str) -> None:
    """Mean WWR error and IoU against mean training minutes, one line per family."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9, 3.6), layout="constrained")
    ax_wwr, ax_iou = fig.subplots(1, 2)
    for family, curve in curves.items():
        x = [c["train_min"] for c in curve]
        ax_wwr.plot(x, [c["wwr_ape"] for c in curve], marker="o", label=family)
        ax_iou.plot(x, [c["footprint_iou"] for c in curve], marker="o", label=family)
    ax_wwr.axhline(WWR_TARGET_PCT, color="grey", ls="--", lw=1)
    ax_iou.axhline(IOU_TARGET, color="grey", ls="--", lw=1)
    ax_wwr.set(xlabel="training minutes (mean over the family)", ylabel="mean WWR error (%)",
               yscale="log")
    ax_iou.set(xlabel="training minutes (mean over the family)", ylabel="mean footprint IoU")
    ax_wwr.legend()
    fig.suptitle(title, fontsize=9)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--results", type=Path, required=True,
                        help="a comparison's results folder (holds neural3d_runs/)")
    parser.add_argument("--resolution", type=int, default=ExtractConfig.resolution,
                        help=f"marching-cubes resolution (default {ExtractConfig.resolution}, "
                             "the comparison's)")
    parser.add_argument("--last", type=int, default=None,
                        help="measure only the last N snapshots of each run (default: all)")
    parser.add_argument("--scenes", nargs="*", default=None, help="only these scene names")
    parser.add_argument("--json", type=Path, default=None, help="also write the figures here")
    parser.add_argument("--plot", type=Path, default=None, help="draw the family curves here")
    parser.add_argument("--threads", type=int, default=2,
                        help="torch CPU threads (default 2; 1 beside another torch job: two "
                             "jobs' threads on 2 cores slow both many times over)")
    args = parser.parse_args(argv)
    runs = sorted(p for p in (args.results / RUNS_FOLDER).iterdir()
                  if (p / "run.json").is_file() and (args.scenes is None or p.name in args.scenes))
    if not runs:
        print(f"no neural3d run folder under {args.results / RUNS_FOLDER}", file=sys.stderr)
        return 2
    try:
        refuse_report_only(trained_scene_dirs(runs), "measure time-to-target for a budget")
    except ValueError as exc:
        parser.error(str(exc))
    torch.set_num_threads(args.threads)
    extract = ExtractConfig(resolution=args.resolution)
    buildings = [run_checks(r, extract, args.last) for r in runs]
    curves = family_curves(buildings)
    made_by = (f"bench/neural3d_checks.py --results {args.results} --resolution "
               f"{args.resolution}, envelope-bench {code_version()}")
    print(markdown(buildings, curves))
    print(f"\n{made_by}")
    if args.json:
        write_json_atomic(args.json, {"buildings": buildings, "families": curves,
                                      "made_by": made_by})
    if args.plot:
        plot(curves, args.plot, made_by)
    return 0


if __name__ == "__main__":
    sys.exit(main())
