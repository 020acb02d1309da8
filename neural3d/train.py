"""Train the semantic SDF on one scene: ``python -m neural3d.train --scene DIR``.

Run folder ``<out>/<scene name>/``: config.json, run.json (scene, normalisation,
device, code version), checkpoint.pt (atomic; every ``checkpoint_every`` steps,
at the end and on Ctrl-C or SIGTERM), log.csv, eval.json. ``--resume`` continues from the
checkpoint and matches an uninterrupted run (optimizer, scheduler and random
generator states are restored).
"""

from __future__ import annotations

import argparse
import copy
import signal
import threading
import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import torch

from envelope.atomic import write_json_atomic
from envelope.classes import CLASS_NAMES
from envelope.cli_errors import add_debug_flag, check_output_folder, exit_cli, run_cli
from envelope.device import resolve_device
from envelope.method_input import MethodInput, require_method_input
from envelope.progress import progress_bar
from envelope.protocols import EVAL_SPLIT, OWN_FACADE_PROTOCOLS, TRAIN_PROTOCOL, Split
from envelope.resources import check_training_resources
from envelope.scene_record import scene_name
from envelope.scenes.scene import read_method_input
from neural3d.config import PRESETS, TrainConfig, preset_config
from neural3d.field.checkpoint import (
    CHECKPOINT_NAME,
    read_checkpoint,
    snapshot_path,
    write_checkpoint,
)
from neural3d.field.trained import TrainedField, build_field
from neural3d.training.data import (
    background_class,
    frames_to_pixels,
    load_frames,
    scene_normalisation,
)
from neural3d.training.evaluate import eval_pixel_subset, evaluate
from neural3d.training.losses import psnr
from neural3d.training.run_folder import (
    check_resumable,
    read_evals,
    read_log,
    read_run_config,
    start_run_folder,
    write_log,
)
from neural3d.training.step import make_occupancy, make_optimizer, train_step

LOG_EVERY = 10  # steps between log.csv rows

Callback = Callable[[int, TrainedField], "bool | None"]


def train(scene: MethodInput, config: TrainConfig, out_dir: Path, *, device: torch.device,
          resume: bool = False, max_seconds: float | None = None,
          callback: Callback | None = None, split: Split = TRAIN_PROTOCOL) -> Path:
    """Train on the scene's ``split`` frames (``train``: the orbit views; ``street``: a street
    capture); returns the run folder ``out_dir/<scene name>``.

    ``scene`` is the scene as a method reads it (no truth:
    :func:`envelope.scenes.scene.read_method_input`), read once by the caller; its ``root``
    names the run folder and is what the run's record and provenance point to.

    ``max_seconds`` stops after that much training time (a checkpoint is written);
    ``callback(step, field)`` runs every ``config.eval_every`` steps and stops
    training when it returns True. Time spent in evaluation and callbacks is not
    counted as training time (``train_s`` in log.csv).

    Raises
    ------
    ValueError
        On an unusable scene (no ``split`` frames, mismatched image sizes, ...), an
        unavailable device, or ``resume`` without a checkpoint or with another config or
        split.
    """
    device = resolve_device(device)
    scene = require_method_input(scene, "neural3d.train")
    scene_dir = scene.root
    run_dir = Path(out_dir) / scene_name(scene_dir)
    bg = background_class(scene)
    check_training_resources(sum(
        round(f.intrinsics.width * config.image_scale) * round(f.intrinsics.height
                                                               * config.image_scale)
        for f in scene.frames_in(split)))
    frames = load_frames(scene, split, image_scale=config.image_scale,
                         with_depth=config.depth_loss)
    if resume:
        norm = check_resumable(run_dir, config, split=split)
    else:
        norm = scene_normalisation(frames, bg, margin=config.scene_box_margin)
        start_run_folder(run_dir, scene_dir, CLASS_NAMES, bg, norm, config, device,
                         len(frames), split=split)
    pixels = frames_to_pixels(frames, norm, device)
    eval_pixels = None
    eval_frames = scene.frames_in(EVAL_SPLIT)
    if eval_frames:
        chosen = load_frames(scene, EVAL_SPLIT, image_scale=config.image_scale)
        pick = torch.linspace(0, len(chosen) - 1, min(config.eval_max_frames, len(chosen)))
        eval_pixels = eval_pixel_subset(
            frames_to_pixels([chosen[int(i)] for i in pick.round()], norm, device),
            config.eval_rays_per_frame, seed=config.seed)

    with torch.random.fork_rng(devices=[]):
        torch.manual_seed(config.seed)
        field = build_field(config.model, len(CLASS_NAMES), norm).to(device)
    optimizer, scheduler = make_optimizer(field, config)
    average = None
    if config.ema_decay > 0:
        average = copy.deepcopy(field).requires_grad_(False)
    gen = torch.Generator(device=device).manual_seed(config.seed)
    step, train_s, eval_s, log_rows, evals = 0, 0.0, 0.0, [], []
    if resume:
        state = read_checkpoint(run_dir / CHECKPOINT_NAME, device)
        field.load_state_dict(state["field"])
        if average is not None:
            average.load_state_dict(state.get("ema", state["field"]))
        optimizer.load_state_dict(state["optimizer"])
        scheduler.load_state_dict(state["scheduler"])
        gen.set_state(state["generator"].cpu())
        step, train_s = int(state["step"]), float(state["train_s"])
        eval_s = float(state.get("eval_s", 0.0))
        log_rows = [r for r in read_log(run_dir) if int(r["step"]) <= step]
        evals = [e for e in read_evals(run_dir) if e["step"] <= step]
    box_min = torch.tensor(norm.box_min_unit, dtype=torch.float32, device=device)
    box_max = torch.tensor(norm.box_max_unit, dtype=torch.float32, device=device)
    classes = tuple(CLASS_NAMES)
    occupancy = make_occupancy(config, box_min, box_max)
    measured = field if average is None else average
    if resume and occupancy is not None and "occupancy" in state:
        occupancy.occupied.copy_(state["occupancy"])

    def save() -> None:
        write_checkpoint(run_dir / CHECKPOINT_NAME, {
            "step": step, "field": field.state_dict(), "optimizer": optimizer.state_dict(),
            "scheduler": scheduler.state_dict(), "generator": gen.get_state(),
            "train_s": train_s, "eval_s": eval_s,
            **({} if occupancy is None else {"occupancy": occupancy.occupied}),
            **({} if average is None else {"ema": average.state_dict()}),
        })
        write_log(run_dir, log_rows)

    # A tqdm bar, or in a task process of the comparison, one that reports to its parent.
    bar = progress_bar(total=config.iterations, initial=step, desc=f"neural3d {run_dir.name}",
                       dynamic_ncols=True, disable=None)
    previous_sigterm = _sigterm_as_interrupt()
    dropped = 0  # candidates the fixed-shape step had no slot for, since the last log row
    try:
        while step < config.iterations:
            tic = time.perf_counter()
            result = train_step(field, optimizer, scheduler, pixels, box_min, box_max, config,
                                step=step, background_class=bg, generator=gen,
                                occupancy=occupancy, average=average)
            step += 1
            train_s += time.perf_counter() - tic
            dropped += result.dropped_samples
            bar.update(1)
            if step % LOG_EVERY == 0 or step == config.iterations:
                row = {"step": step, "train_s": round(train_s, 3), "loss": result.loss,
                       **result.parts,
                       "psnr": psnr(result.render.rgb.detach(), pixels.rgb[result.pixel_index]),
                       "inv_s": float(field.inv_s().detach()), "lr": scheduler.get_last_lr()[0],
                       **({"dropped_samples": dropped} if config.sample_buffer else {})}
                dropped = 0
                log_rows.append(row)
                write_log(run_dir, log_rows)
                bar.set_postfix(loss=f"{row['loss']:.4f}", psnr=f"{row['psnr']:.2f}")
            stop = max_seconds is not None and train_s >= max_seconds
            if step % config.checkpoint_every == 0:
                save()
            if step % config.eval_every == 0 or step == config.iterations or stop:
                write_checkpoint(snapshot_path(run_dir, step),
                                 {"step": step, "field": measured.state_dict()})
                if eval_pixels is not None:
                    tic = time.perf_counter()
                    figures = evaluate(measured, eval_pixels, box_min, box_max, config, step=step,
                                       background_class=bg)
                    eval_s += time.perf_counter() - tic
                    evals.append({"step": step, "train_s": round(train_s, 3),
                                  "eval_s": round(eval_s, 3), "eval_rays": len(eval_pixels),
                                  **figures})
                    write_json_atomic(run_dir / "eval.json", {"evaluations": evals})
                if callback is not None:
                    measured.eval()
                    answer = callback(step, TrainedField(measured, norm, scene_dir=scene_dir,
                                                         class_names=classes, split=split))
                    measured.train()
                    stop = stop or answer is True
            if stop:
                break
    except KeyboardInterrupt:
        save()
        raise
    finally:
        bar.close()
        if previous_sigterm is not None:
            signal.signal(signal.SIGTERM, previous_sigterm)
    save()
    return run_dir


def _raise_interrupt(signum: int, frame: object) -> None:
    raise KeyboardInterrupt(f"signal {signum}")


def _sigterm_as_interrupt():
    """Make SIGTERM raise KeyboardInterrupt (so it saves a checkpoint as Ctrl-C does).

    Returns the previous handler to restore, or None off the main thread (where
    Python cannot install handlers; such a caller handles its own signals).
    """
    if threading.current_thread() is not threading.main_thread():
        return None
    return signal.signal(signal.SIGTERM, _raise_interrupt)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m neural3d.train",
        description="Train the semantic neural SDF on a scene's train (orbit) or street frames "
                    "(RGB + semantic masks + poses). Writes <out>/<scene name>/ with "
                    "config.json, run.json, checkpoint.pt, log.csv and eval.json.")
    parser.add_argument("--scene", type=Path, required=True, help="scene folder "
                        "(transforms.json with frames of the --split)")
    parser.add_argument("--split", choices=OWN_FACADE_PROTOCOLS, default=TRAIN_PROTOCOL,
                        help="the frames to train on: train (the orbit views, default) or "
                             "street (a street capture: scenes made with --street)")
    parser.add_argument("--preset", choices=PRESETS, default=None,
                        help="paper (8x256 MLP, GPU), fast (grid, default) or tiny (tests)")
    parser.add_argument("--out", type=Path, default=Path("runs/neural3d"),
                        help="folder of run folders (default runs/neural3d)")
    parser.add_argument("--device", default="cpu", help="cpu (default), cuda or cuda:N")
    parser.add_argument("--resume", action="store_true",
                        help="continue from the run folder's checkpoint with its saved config")
    parser.add_argument("--max-minutes", type=float, default=None,
                        help="stop after this many minutes of training (a checkpoint is kept)")
    parser.add_argument("--iterations", type=int, default=None, help="override the preset")
    parser.add_argument("--eval-every", type=int, default=None,
                        help="steps between held-out evaluations (override the preset)")
    parser.add_argument("--eval-rays", type=int, default=None,
                        help="random pixels scored per eval frame (0 = every pixel; preset "
                             "default 1024); evaluation time is reported as eval_s")
    parser.add_argument("--depth-loss", action="store_true",
                        help="variant: also supervise rendered depth with the depth images")
    parser.add_argument("--sample-buffer", type=int, default=None, metavar="N",
                        help="variant: the fixed-shape training step, the field evaluated at "
                             "N sample slots a batch (0 = off, the presets' default)")
    add_debug_flag(parser)
    args = parser.parse_args(argv)
    run_dir = Path(args.out) / scene_name(args.scene)

    def body() -> int:
        if args.resume and args.preset is None and (run_dir / "config.json").is_file():
            config = read_run_config(run_dir)
        else:
            config = preset_config(args.preset or "fast")
            if args.iterations is not None:
                config = replace(config, iterations=args.iterations)
            if args.depth_loss:
                config = replace(config, depth_loss=True)
            if args.sample_buffer is not None:
                config = replace(config, sample_buffer=args.sample_buffer)
            if args.eval_every is not None:
                config = replace(config, eval_every=args.eval_every)
            if args.eval_rays is not None:
                config = replace(config, eval_rays_per_frame=args.eval_rays)
        if args.max_minutes is not None and not args.max_minutes > 0:
            raise ValueError(f"--max-minutes must be > 0, got {args.max_minutes}")
        check_output_folder(args.out)
        max_s = None if args.max_minutes is None else 60.0 * args.max_minutes
        device = resolve_device(args.device)
        print(train(read_method_input(args.scene), config, args.out, device=device,
                    resume=args.resume, max_seconds=max_s, split=args.split))
        return 0

    def interrupted() -> str:
        if (run_dir / CHECKPOINT_NAME).is_file():
            return f"interrupted: checkpoint saved in {run_dir}; continue with --resume"
        return "interrupted before the first checkpoint; run the same command again"

    return run_cli("neural3d.train", body, debug=args.debug, interrupted=interrupted)


if __name__ == "__main__":
    exit_cli(main())
