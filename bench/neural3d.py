"""Speed and time-to-accuracy of the semantic neural SDF; prints Markdown, writes JSON.

    python bench/neural3d.py speed --scene DIR [--device cpu|cuda] [--steps 20] [--warmup 250]
        [--cases grid,mlp-paper,mlp-fast]
    python bench/neural3d.py converge --benchmark DIR [--minutes 30] [--check-every 100]

``speed``: training iterations per second of each backbone at its preset's
batch (``fast`` = grid, ``paper`` = mlp) and of the mlp at ``fast``'s batch,
on one scene, timed over ``--steps`` steps after ``--warmup`` untimed ones. The
occupancy grid (where the config has one) is refreshed from step 0 on, so the
timed steps skip empty space as training does once it is under way. Given per
wall-clock second and per CPU second of this process: on a machine shared with
other jobs the CPU figure is the one that depends least on the neighbours.

``converge``: trains ``fast`` on every scene folder of ``--benchmark`` (e.g. the
tiny preset, one building per family) and every ``--check-every`` iterations
meshes and measures the field with part 2's ``neural3d.extract.measure_field``;
reports the training time until WWR error <= 5 % and footprint IoU >= 0.96
(the targets), the final figures and their spread (max - min) over the last
three checks. Measuring time is not training time.
"""

from __future__ import annotations

import argparse
import copy
import json
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

# Run as a script, this file's folder is sys.path[0]: put the repository root there instead.
sys.path[0] = str(Path(__file__).resolve().parent.parent)

import torch  # noqa: E402

from envelope.atomic import write_json_atomic  # noqa: E402
from envelope.device import resolve_device  # noqa: E402
from envelope.scenes.scene import read_method_input, read_scene  # noqa: E402
from neural3d.config import TrainConfig, preset_config  # noqa: E402
from neural3d.field.trained import TrainedField, build_field  # noqa: E402
from neural3d.train import train  # noqa: E402
from neural3d.training.data import (  # noqa: E402
    background_class,
    frames_to_pixels,
    load_frames,
    scene_normalisation,
)
from neural3d.training.step import (  # noqa: E402
    StepResult,
    make_occupancy,
    make_optimizer,
    train_step,
)

WWR_TARGET_PCT = 5.0
IOU_TARGET = 0.96


@dataclass
class TrainingState:
    """A fresh field on a scene's train frames and everything its training steps need."""

    field: torch.nn.Module
    optimizer: torch.optim.Optimizer
    scheduler: torch.optim.lr_scheduler.LRScheduler
    pixels: object  # neural3d.training.data.Pixels
    box_min: torch.Tensor  # "(3,)" normalised frame
    box_max: torch.Tensor
    background_class: int
    generator: torch.Generator
    occupancy: object  # neural3d.rendering.occupancy.OccupancyGrid | None
    average: torch.nn.Module | None
    config: TrainConfig

    def step(self, i: int) -> StepResult:
        """Training step ``i`` (``train_step``, weight averaging included)."""
        return train_step(self.field, self.optimizer, self.scheduler, self.pixels, self.box_min,
                          self.box_max, self.config, step=i,
                          background_class=self.background_class, generator=self.generator,
                          occupancy=self.occupancy, average=self.average)


def training_state(scene_dir: Path, config: TrainConfig, device: torch.device) -> TrainingState:
    """A fresh field on ``scene_dir``'s train frames, set up as ``neural3d.train`` sets it up."""
    scene = read_method_input(scene_dir)  # never the truth, as in neural3d.train
    bg = background_class(scene)
    frames = load_frames(scene, "train", image_scale=config.image_scale)
    norm = scene_normalisation(frames, bg, margin=config.scene_box_margin)
    px = frames_to_pixels(frames, norm, device)
    with torch.random.fork_rng(devices=[]):
        torch.manual_seed(config.seed)
        field = build_field(config.model, len(scene.semantic_classes), norm).to(device)
    optimizer, scheduler = make_optimizer(field, config)
    average = copy.deepcopy(field).requires_grad_(False) if config.ema_decay > 0 else None
    lo = torch.tensor(norm.box_min_unit, dtype=torch.float32, device=device)
    hi = torch.tensor(norm.box_max_unit, dtype=torch.float32, device=device)
    return TrainingState(field, optimizer, scheduler, px, lo, hi, bg,
                         torch.Generator(device=device).manual_seed(config.seed),
                         make_occupancy(config, lo, hi), average, config)


def training_steps(scene_dir: Path, config: TrainConfig, device: torch.device
                   ) -> Callable[[int], None]:
    """``step(i)``: training step ``i`` (``train_step``, weight averaging included) of a fresh
    field on ``scene_dir``'s train frames, as ``neural3d.train`` runs it; synchronised on CUDA.
    """
    state = training_state(scene_dir, config, device)

    def step(i: int) -> None:
        state.step(i)
        if device.type == "cuda":
            torch.cuda.synchronize(device)

    return step


def iterations_per_second(scene_dir: Path, config: TrainConfig, device: torch.device,
                          steps: int, warmup: int = 1) -> tuple[float, float]:
    """(iterations per wall second, per process CPU second) of the training step.

    ``warmup`` untimed steps first; the occupancy grid (if any) starts at step 0.
    """
    step = training_steps(scene_dir, replace(config, occupancy_start=0), device)
    warmup = max(warmup, 1)  # allocator, first calls, the grid's first refreshes
    for i in range(warmup):
        step(i)
    wall, cpu = time.perf_counter(), time.process_time()
    for i in range(warmup, warmup + steps):
        step(i)
    return steps / (time.perf_counter() - wall), steps / (time.process_time() - cpu)


def speed(args: argparse.Namespace) -> dict:
    device = resolve_device(args.device)
    fast, paper = preset_config("fast"), preset_config("paper")
    cases = {
        "grid": ("grid (fast preset)", fast),
        "mlp-paper": ("mlp (paper preset)", paper),
        "mlp-fast": ("mlp at the fast batch", replace(fast, model=paper.model)),
    }
    unknown = set(args.cases) - set(cases)
    if unknown:
        raise ValueError(f"unknown --cases {', '.join(sorted(unknown))}; "
                         f"choose from {', '.join(cases)}")
    rows = []
    for key in args.cases:
        name, config = cases[key]
        per_wall, per_cpu = iterations_per_second(args.scene, config, device, args.steps,
                                                  args.warmup)
        samples = config.samples_uniform + config.samples_importance
        rows.append({"case": name, "device": str(device), "rays": config.rays_per_batch,
                     "samples": samples, "it_per_s": per_wall, "it_per_cpu_s": per_cpu})
        print(f"| {name} | {device} | {config.rays_per_batch} | {samples} | {per_wall:.3f} | "
              f"{per_cpu:.3f} |", flush=True)
    return {"speed": rows}


def converge_scene(scene_dir: Path, config: TrainConfig, extract, device: torch.device,
                   out_dir: Path, minutes: float, stop_at_target: bool) -> dict:
    """Train one scene, measuring every ``config.eval_every`` steps; the checks and targets."""
    from metrics.score.errors import building_errors
    from neural3d.extract import measure_field

    truth = read_scene(scene_dir).building
    checks: list[dict] = []
    start, measuring = time.perf_counter(), 0.0

    def check(step: int, field: TrainedField) -> bool:
        nonlocal measuring
        tic = time.perf_counter()
        result, _ = measure_field(field, extract, device=device)
        errors = building_errors(result, truth)
        wall_s = tic - start - measuring
        row = {"step": step, "wall_s": wall_s, "it_per_s": step / wall_s,
               "wwr_ape": errors.wwr_ape, "window_ape": errors.window_ape,
               "facade_ape": errors.facade_ape, "footprint_iou": errors.footprint_iou}
        measuring += time.perf_counter() - tic
        checks.append(row)
        print(f"  {scene_dir.name} step {step}: {row}", flush=True)
        return stop_at_target and on_target(row)

    train(read_method_input(scene_dir), config, out_dir, device=device,
          max_seconds=60.0 * minutes, callback=check)
    return {"scene": scene_dir.name, "family": truth.type if truth else None, "checks": checks,
            "target_reached": next((c for c in checks if on_target(c)), None),
            "final": checks[-1] if checks else None, "last3_spread": last_checks_spread(checks)}


def last_checks_spread(checks: list[dict], n: int = 3) -> dict[str, float | None]:
    """Max - min of WWR error (points of %) and footprint IoU over the last ``n`` checks."""
    tail = checks[-n:]

    def spread(key: str) -> float | None:
        values = [c[key] for c in tail if c.get(key) is not None]
        return max(values) - min(values) if len(values) == n else None

    return {"wwr_ape": spread("wwr_ape"), "footprint_iou": spread("footprint_iou")}


def on_target(row: dict) -> bool:
    return (row["wwr_ape"] is not None and row["wwr_ape"] <= WWR_TARGET_PCT
            and row["footprint_iou"] is not None and row["footprint_iou"] >= IOU_TARGET)


def converge(args: argparse.Namespace) -> dict:
    from neural3d.extraction.extract_config import ExtractConfig

    device = resolve_device(args.device)
    config = replace(with_overrides(preset_config("fast"), args.set),
                     eval_every=args.check_every, checkpoint_every=args.check_every)
    extract = ExtractConfig(resolution=args.resolution)
    scenes = sorted(p for p in Path(args.benchmark).iterdir() if (p / "transforms.json").is_file()
                    and (args.scenes is None or p.name in args.scenes))
    if not scenes:
        raise ValueError(f"{args.benchmark} holds no scene folder (transforms.json)")
    out_dir = Path(args.out) if args.out else Path(tempfile.mkdtemp(prefix="bench_neural3d_"))
    results = []
    for scene_dir in scenes:
        r = converge_scene(scene_dir, config, extract, device, out_dir, args.minutes,
                           args.stop_at_target)
        results.append(r)
        reached, final = r["target_reached"], r["final"] or {}
        minutes = f"{reached['wall_s'] / 60:.1f}" if reached else "not reached"
        sp = r["last3_spread"]
        print(f"| {r['scene']} | {minutes} | {final.get('step')} | {final.get('wwr_ape')} | "
              f"{final.get('footprint_iou')} | {sp['wwr_ape']} | {sp['footprint_iou']} |",
              flush=True)
    return {"converge": results, "device": str(device), "config": "fast",
            "overrides": list(args.set)}


def with_overrides(config: TrainConfig, settings: list[str]) -> TrainConfig:
    """``config`` with ``key=value`` settings (``model.key`` for the field; JSON values)."""
    train_kw, model_kw = {}, {}
    for item in settings:
        key, sep, value = item.partition("=")
        if not sep:
            raise ValueError(f"--set expects key=value, got {item!r}")
        try:
            parsed = json.loads(value)
        except json.JSONDecodeError:
            parsed = value  # a bare string such as mlp
        if key.startswith("model."):
            model_kw[key[len("model."):]] = parsed
        else:
            train_kw[key] = parsed
    try:
        return replace(config, **train_kw, model=replace(config.model, **model_kw))
    except TypeError as exc:
        raise ValueError(f"bad --set: {exc}") from exc


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    sp = sub.add_parser("speed", help="training iterations per second per backbone")
    sp.add_argument("--scene", type=Path, required=True, help="a scene folder")
    sp.add_argument("--steps", type=int, default=20, help="timed steps (default 20)")
    sp.add_argument("--warmup", type=int, default=250,
                    help="untimed steps first, so the occupancy grid is refreshed (default 250)")
    sp.add_argument("--cases", type=lambda v: v.split(","), default=["grid", "mlp-paper",
                                                                     "mlp-fast"],
                    help="comma-separated: grid, mlp-paper, mlp-fast (default all)")
    cv = sub.add_parser("converge", help="time until the targets on a benchmark folder")
    cv.add_argument("--benchmark", type=Path, required=True, help="folder of scene folders")
    cv.add_argument("--minutes", type=float, default=30.0, help="training limit per building")
    cv.add_argument("--check-every", type=int, default=100, help="iterations between checks")
    cv.add_argument("--resolution", type=int, default=128, help="marching-cubes resolution")
    cv.add_argument("--stop-at-target", action="store_true",
                    help="stop a building's training once both targets are met")
    cv.add_argument("--out", type=Path, default=None, help="run folders (default: a temp dir)")
    cv.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="override a fast-preset field, e.g. model.grid_coarse_to_fine_steps=300")
    cv.add_argument("--scenes", nargs="*", default=None, help="only these scene names")
    for p in (sp, cv):
        p.add_argument("--device", default="cpu")
        p.add_argument("--json", type=Path, default=None, help="also write the figures here")
    args = parser.parse_args(argv)
    try:
        print(f"torch threads: {torch.get_num_threads()}", flush=True)
        if args.command == "speed":
            print("| case | device | rays | samples | it/s (wall) | it/s (CPU) |\n"
                  "|---|---|---|---|---|---|")
            figures = speed(args)
        else:
            print("| scene | minutes to target | final step | WWR APE % | footprint IoU | "
                  "WWR spread, last 3 checks | IoU spread |\n|---|---|---|---|---|---|---|")
            figures = converge(args)
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if args.json:
        write_json_atomic(args.json, figures)
    return 0


if __name__ == "__main__":
    sys.exit(main())
