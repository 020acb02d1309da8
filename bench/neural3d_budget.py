"""Time to accuracy of neural3d: WWR error and footprint IoU against training time per family.

    python bench/neural3d_budget.py --benchmark DIR --steps 1000 2000 [--seeds 0 1]
        [--set KEY=VALUE ...] [--scenes NAME ...] [--resolution 128] [--threads 1]
        [--out DIR] [--json FILE] [--plot FILE.png]

For every step budget of ``--steps`` and every training seed of ``--seeds``,
trains the ``fast`` preset (with ``--set`` overrides) on each scene folder of
``--benchmark`` for exactly that many steps (the whole schedule: warm-up and
cosine decay end at the budget, as in a comparison with ``--neural3d-steps``),
then meshes and measures the finished field (``neural3d.extract.measure_field``,
marching cubes at ``--resolution``) against the scene's truth. Training time is
the run's own ``train_s`` (evaluation and measuring excluded).

Prints, in Markdown, a row per building, budget and seed, then per family and
budget: mean training minutes, mean WWR error and IoU, how many runs met the
targets (WWR error <= 5 %, IoU >= 0.96) and the seed-to-seed spread (max - min
over seeds, averaged over the buildings). The default step budget is the
smallest whose every run meets the targets. Finished runs under ``--out`` are
reused (a rerun measures only what is missing): a sweep can be stopped and
resumed.
"""

from __future__ import annotations

import argparse
import statistics
import sys
from dataclasses import replace
from pathlib import Path

# Run as a script, this file's folder is sys.path[0]: put the repository root there instead.
sys.path[0] = str(Path(__file__).resolve().parent.parent)

import torch  # noqa: E402

from bench.neural3d import IOU_TARGET, WWR_TARGET_PCT, on_target, with_overrides  # noqa: E402
from dataset.set_roles import refuse_report_only  # noqa: E402
from envelope.atomic import write_json_atomic  # noqa: E402
from envelope.results import code_version  # noqa: E402
from envelope.scenes.scene import read_scene  # noqa: E402
from neural3d.config import TrainConfig, config_to_dict, preset_config  # noqa: E402
from neural3d.field.checkpoint import CHECKPOINT_NAME, read_checkpoint  # noqa: E402

CPU = torch.device("cpu")


def trained_run(scene_dir: Path, config: TrainConfig, out_dir: Path) -> tuple[Path, float]:
    """(run folder, training seconds) of ``config`` on ``scene_dir``: trained now, or reused
    when ``out_dir`` already holds that run finished with the same config."""
    from envelope.scenes.scene import read_method_input
    from neural3d.train import train
    from neural3d.training.run_folder import read_run_config

    scene = read_method_input(scene_dir)
    run_dir = out_dir / scene_dir.name
    checkpoint = run_dir / CHECKPOINT_NAME
    if not (checkpoint.is_file() and config_to_dict(read_run_config(run_dir))
            == config_to_dict(config)):
        run_dir = train(scene, config, out_dir, device=CPU)
    state = read_checkpoint(checkpoint, CPU)
    if int(state["step"]) < config.iterations:
        run_dir = train(scene, config, out_dir, device=CPU, resume=True)
        state = read_checkpoint(checkpoint, CPU)
    return run_dir, float(state["train_s"])


def measure_run(run_dir: Path, scene_dir: Path, resolution: int) -> dict:
    """The finished field's errors against the truth (WWR, window, facade APE %, IoU)."""
    from metrics.score.errors import building_errors
    from neural3d.extract import measure_field
    from neural3d.extraction.extract_config import ExtractConfig
    from neural3d.field.trained import load_trained_field

    field = load_trained_field(run_dir, device=CPU)
    result, _ = measure_field(field, ExtractConfig(resolution=resolution), device=CPU)
    errors = building_errors(result, read_scene(scene_dir).building)
    return {"wwr_ape": errors.wwr_ape, "window_ape": errors.window_ape,
            "facade_ape": errors.facade_ape, "footprint_iou": errors.footprint_iou}


def family_summary(rows: list[dict]) -> list[dict]:
    """Per family and step budget: means, runs on target, seed-to-seed spread."""
    out = []
    for family in sorted({r["family"] for r in rows}, key=str):
        for steps in sorted({r["steps"] for r in rows if r["family"] == family}):
            group = [r for r in rows if r["family"] == family and r["steps"] == steps]
            spreads = {"wwr_ape": [], "footprint_iou": []}
            for scene in {r["scene"] for r in group}:
                runs = [r for r in group if r["scene"] == scene]
                for key in spreads:
                    values = [r[key] for r in runs if r[key] is not None]
                    if len(values) > 1:
                        spreads[key].append(max(values) - min(values))
            out.append({
                "family": family, "steps": steps, "runs": len(group),
                "train_min": statistics.fmean(r["train_s"] / 60 for r in group),
                "wwr_ape": _mean([r["wwr_ape"] for r in group]),
                "footprint_iou": _mean([r["footprint_iou"] for r in group]),
                "on_target": sum(on_target(r) for r in group),
                "seed_spread_wwr": _mean(spreads["wwr_ape"]),
                "seed_spread_iou": _mean(spreads["footprint_iou"]),
            })
    return out


def _mean(values: list[float | None]) -> float | None:
    values = [v for v in values if v is not None]
    return statistics.fmean(values) if values else None


def _fmt(value: float | None, digits: int) -> str:
    return "n/a" if value is None else f"{value:.{digits}f}"


def markdown(rows: list[dict], summary: list[dict]) -> str:
    lines = ["| building | steps | seed | training min | WWR error % | window % | facade % | "
             "IoU |", "|---|---|---|---|---|---|---|---|"]
    lines += [f"| {r['scene']} | {r['steps']} | {r['seed']} | {r['train_s'] / 60:.2f} | "
              f"{_fmt(r['wwr_ape'], 2)} | {_fmt(r['window_ape'], 2)} | "
              f"{_fmt(r['facade_ape'], 2)} | {_fmt(r['footprint_iou'], 3)} |" for r in rows]
    lines += ["", "| family | steps | runs | mean training min | mean WWR error % | mean IoU | "
              "on target | seed spread WWR (pts) | seed spread IoU |",
              "|---|---|---|---|---|---|---|---|---|"]
    lines += [f"| {s['family']} | {s['steps']} | {s['runs']} | {s['train_min']:.2f} | "
              f"{_fmt(s['wwr_ape'], 2)} | {_fmt(s['footprint_iou'], 3)} | "
              f"{s['on_target']}/{s['runs']} | {_fmt(s['seed_spread_wwr'], 2)} | "
              f"{_fmt(s['seed_spread_iou'], 3)} |" for s in summary]
    return "\n".join(lines)


def plot(summary: list[dict], path: Path, title: str) -> None:
    """Mean WWR error and IoU against mean training minutes, one line per family."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9, 3.6), layout="constrained")
    ax_wwr, ax_iou = fig.subplots(1, 2)
    for family in sorted({s["family"] for s in summary}, key=str):
        curve = [s for s in summary if s["family"] == family]
        x = [s["train_min"] for s in curve]
        ax_wwr.plot(x, [s["wwr_ape"] for s in curve], marker="o", label=family)
        ax_iou.plot(x, [s["footprint_iou"] for s in curve], marker="o", label=family)
    ax_wwr.axhline(WWR_TARGET_PCT, color="grey", ls="--", lw=1)
    ax_iou.axhline(IOU_TARGET, color="grey", ls="--", lw=1)
    ax_wwr.set(xlabel="training minutes (mean)", ylabel="mean WWR error (%)")
    ax_iou.set(xlabel="training minutes (mean)", ylabel="mean footprint IoU")
    ax_wwr.legend()
    fig.suptitle(title, fontsize=9)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--benchmark", type=Path, required=True, help="folder of scene folders")
    parser.add_argument("--steps", type=int, nargs="+", required=True,
                        help="step budgets, each trained with its whole schedule")
    parser.add_argument("--seeds", type=int, nargs="+", default=[0],
                        help="training seeds (TrainConfig.seed; default 0)")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="override a fast-preset field (model.KEY for the field)")
    parser.add_argument("--scenes", nargs="*", default=None, help="only these scene names")
    parser.add_argument("--resolution", type=int, default=128,
                        help="marching-cubes resolution (default 128, the default run's)")
    parser.add_argument("--threads", type=int, default=1, help="torch CPU threads (1)")
    parser.add_argument("--out", type=Path, default=Path(".cache/neural3d-budget"),
                        help="run folders, reused by a rerun (default .cache/neural3d-budget)")
    parser.add_argument("--json", type=Path, default=None, help="also write the figures here")
    parser.add_argument("--plot", type=Path, default=None, help="draw the family curves here")
    args = parser.parse_args(argv)
    try:
        base = with_overrides(preset_config("fast"), args.set)
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    scenes = sorted(p for p in args.benchmark.iterdir() if (p / "transforms.json").is_file()
                    and (args.scenes is None or p.name in args.scenes))
    try:
        refuse_report_only(scenes, "choose a training budget")
    except ValueError as exc:
        parser.error(str(exc))
    if not scenes:
        print(f"error: {args.benchmark} holds no scene folder (transforms.json)", file=sys.stderr)
        return 2
    torch.set_num_threads(args.threads)
    tag = "-".join(args.set).replace("/", "_") or "fast"
    rows = []
    for steps in args.steps:
        for seed in args.seeds:
            config = replace(base, iterations=steps, seed=seed, eval_every=steps,
                             checkpoint_every=steps)
            out_dir = args.out / tag / f"steps{steps}-seed{seed}"
            for scene_dir in scenes:
                run_dir, train_s = trained_run(scene_dir, config, out_dir)
                row = {"scene": scene_dir.name, "family": read_scene(scene_dir).building.type,
                       "steps": steps, "seed": seed, "train_s": train_s,
                       **measure_run(run_dir, scene_dir, args.resolution)}
                rows.append(row)
                print(f"  {row}", file=sys.stderr, flush=True)
    summary = family_summary(rows)
    made_by = (f"bench/neural3d_budget.py --benchmark {args.benchmark} --set "
               f"{' '.join(args.set) or '(none)'}, {args.threads} threads, "
               f"envelope-bench {code_version()}")
    print(markdown(rows, summary))
    print(f"\n{made_by}")
    if args.json:
        write_json_atomic(args.json, {"runs": rows, "families": summary, "made_by": made_by})
    if args.plot:
        plot(summary, args.plot, made_by)
    return 0


if __name__ == "__main__":
    sys.exit(main())
