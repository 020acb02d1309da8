"""``python -m segment.train``: train the segmenter on renders of buildings never evaluated,
and on labelled real photos if given.

Stages: load the training scenes (refusing evaluated presets) and split them by
building into train and validation; with real sets (``--labelmefacade``, ``--cmp``),
load their ``train`` and ``val`` photos from the committed split lists
(:mod:`segment.real_training`; ``test`` photos are never read); measure class weights;
run ``steps`` optimiser steps on augmented crops (AdamW, one-cycle learning rate; with
real sets a ``real_share`` of each batch is real crops, and every crop takes
:data:`segment.augment.REAL_PHOTO_AUGMENT`), validating every ``validate_every`` steps;
write the weights of the best validation step (the highest mean IoU of background, wall
and window: the classes a facade measurement reads; on the real validation photos when
real sets are given, else on the validation buildings) with their training record (data,
seeds, config, code fingerprints, libraries, wall time) atomically. Ctrl-C writes nothing.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import torch
from torch.nn import functional as F
from tqdm import tqdm

from envelope.classes import CLASS_NAMES, NUM_CLASSES, SemanticClass
from envelope.cli_errors import add_debug_flag, check_output_folder, exit_cli, run_cli
from envelope.provenance import file_fingerprint, make_provenance
from segment.augment import IGNORE_LABEL, REAL_PHOTO_AUGMENT, AugmentConfig
from segment.evaluate import confusion_matrix, evenly_spaced, iou_per_class, mean_iou
from segment.network import UNet, UNetConfig
from segment.real_sets import SET_NAMES, SOURCES
from segment.real_sets.splits import LIST_DIR
from segment.real_training import RealSource, real_sources
from segment.segmenter import predict_labels
from segment.training_data import (
    PreloadedSource,
    TrainingScene,
    class_weights,
    load_training_scenes,
    preload,
    sample_batch,
    split_by_building,
)
from segment.weights import save_weights

SELECTION_CLASSES = (SemanticClass.BACKGROUND, SemanticClass.WALL, SemanticClass.WINDOW)
"""The classes whose mean validation IoU picks the weights kept: what a facade measurement
reads (where the building is, and its wall and windows)."""


@dataclass(frozen=True)
class TrainConfig:
    """Everything that fixes a training run (recorded with the weights).

    ``steps`` optimiser steps of ``batch`` crops; ``learning_rate`` is the one-cycle peak.
    ``val_every``: every ``val_every``-th building (sorted by name) validates instead of
    training (0: none; the last step's weights are kept). ``validate_every``: steps
    between validations, on ``val_frames`` evenly spaced frames per validation scene.
    ``max_minutes``: a safety cap; a run it stops is marked ``cut_short``.
    ``real_share``: the share of each batch drawn from real photos when real sets are
    given; ``real_val_photos``: validation photos per real set. With a network that has a
    ``working_long_side_px``, every training frame is read once and kept at that scale
    (:func:`segment.training_data.preload`), ``render_frames`` evenly spaced frames of
    each render building (0: all).
    """

    steps: int = 6000
    batch: int = 12
    learning_rate: float = 3e-3
    weight_decay: float = 1e-4
    seed: int = 0
    threads: int = 2
    val_every: int = 6
    validate_every: int = 250
    val_frames: int = 8
    max_minutes: float = 45.0
    real_share: float = 0.5
    real_val_photos: int = 24
    render_frames: int = 0
    network: UNetConfig = field(default_factory=lambda: UNetConfig(base_channels=8, levels=6))
    augment: AugmentConfig = field(default_factory=AugmentConfig)

    def __post_init__(self) -> None:
        if min(self.steps, self.batch, self.threads, self.validate_every, self.val_frames) < 1:
            raise ValueError("steps, batch, threads, validate_every and val_frames must be >= 1")
        if self.val_every < 0 or self.learning_rate <= 0 or self.max_minutes <= 0:
            raise ValueError("val_every must be >= 0, learning_rate and max_minutes > 0")
        if self.render_frames < 0:
            raise ValueError("render_frames must be >= 0 (0: every frame)")
        if not 0 <= self.real_share <= 1 or self.real_val_photos < 1:
            raise ValueError("real_share must be in [0, 1] and real_val_photos >= 1")


@dataclass
class _Best:
    step: int = 0
    score: float = -1.0
    iou: tuple[float, ...] = ()
    state: dict[str, torch.Tensor] | None = None


def train_segmenter(folders: Sequence[Path], out: Path, config: TrainConfig = TrainConfig(),
                    *, real: Mapping[str, Path] | None = None,
                    progress: bool = True) -> dict[str, Any]:
    """Train on the scenes of ``folders`` and the real sets ``real`` (set name -> folder,
    :mod:`segment.real_sets`), write ``out`` (and ``out.json``); return the training record.

    Raises
    ------
    ValueError
        Bad folders or scenes (see :func:`segment.training_data.load_training_scenes`),
        or no building left to train on after the split.
    """
    start, cpu_start = time.perf_counter(), time.process_time()
    previous_threads = torch.get_num_threads()
    torch.set_num_threads(config.threads)
    cv2.setNumThreads(1)
    try:
        scenes = load_training_scenes(folders)
        train, val = split_by_building(scenes, config.val_every)
        if not train:
            raise ValueError("no building left to train on; lower --val-every or add scenes")
        real_train, real_val = (real_sources(real, config.real_val_photos) if real
                                else ([], []))
        # The record names the code as it was when training started.
        inputs: dict[str, Any] = {"scenes": {f"{s.record['folder']}/{s.name}":
                                             s.record["transforms"] for s in train + val}}
        if real:
            inputs["real_split_lists"] = {n: file_fingerprint(LIST_DIR / f"{n}.csv")
                                          for n in real}
        provenance = make_provenance(
            asdict(config), modules=("segment", "envelope", "dataset"), inputs=inputs,
            libraries=("torch", "numpy", "opencv-contrib-python-headless"))
        rng = np.random.default_rng(config.seed)
        torch.manual_seed(config.seed)
        long_side = config.network.working_long_side_px
        if long_side is not None:
            train = preload(train, long_side, config.render_frames, progress)
            real_train = preload(real_train, long_side, 0, progress)
        weights = class_weights([*train, *real_train], rng)
        model = UNet(config.network).to(memory_format=torch.channels_last)
        best, history, steps_run = _optimise(model, (train, real_train), (val, real_val),
                                             weights, config, rng, start, progress)
        if best.state is not None:
            model.load_state_dict(best.state)
        # Milliseconds: a few steps on a fast machine take well under 0.1 s.
        times = {"wall_time_s": round(time.perf_counter() - start, 3),
                 "cpu_time_s": round(time.process_time() - cpu_start, 3)}
        record = _record(config, [*train, *real_train], [*val, *real_val], weights, best,
                         history, steps_run, times)
        record["training_sets"] = training_sets(real or {})
        record["provenance"] = provenance.to_json_dict()
        save_weights(out, model, record)
        return record
    finally:
        torch.set_num_threads(previous_threads)


Source = TrainingScene | RealSource | PreloadedSource


def _optimise(model: UNet, train: tuple[list[Source], list[Source]],
              val: tuple[list[TrainingScene], list[RealSource]], weights: np.ndarray,
              config: TrainConfig, rng: np.random.Generator, start: float,
              progress: bool) -> tuple[_Best, list[dict[str, float]], int]:
    """The training loop: (best validation step, history, steps run). ``train`` and ``val``
    are (render scenes, real-photo sources); the weights kept are picked on the real
    validation photos when there are any, else on the validation buildings."""
    renders, real = train
    n_real = int(round(config.batch * config.real_share)) if real else 0
    selection = val[1] if val[1] else val[0]
    optimiser = torch.optim.AdamW(model.parameters(), lr=config.learning_rate,
                                  weight_decay=config.weight_decay)
    schedule = torch.optim.lr_scheduler.OneCycleLR(optimiser, config.learning_rate,
                                                   total_steps=config.steps, pct_start=0.1)
    class_w = torch.tensor(weights, dtype=torch.float32)
    best, history, losses = _Best(), [], []
    bar = tqdm(range(1, config.steps + 1), desc="train segmenter", unit="step",
               disable=not progress)
    step = 0
    for step in bar:
        model.train()
        x, y = _mixed_batch(renders, real, config.batch - n_real, n_real, config, rng)
        loss = F.cross_entropy(model(x), y, weight=class_w, ignore_index=IGNORE_LABEL)
        optimiser.zero_grad(set_to_none=True)
        loss.backward()
        optimiser.step()
        schedule.step()
        losses.append(loss.item())
        over_time = time.perf_counter() - start > config.max_minutes * 60
        if step % config.validate_every == 0 or step == config.steps or over_time:
            entry = {"step": step, "loss": float(np.mean(losses)),
                     "minutes": (time.perf_counter() - start) / 60}
            losses = []
            if val[0] and val[1]:
                render_iou = validation_iou(model, val[0], config.val_frames, config.threads)
                entry["val_renders_window_iou"] = float(render_iou[SemanticClass.WINDOW])
            if selection:
                iou = validation_iou(model, selection, config.val_frames, config.threads)
                entry["val_window_iou"] = float(iou[SemanticClass.WINDOW])
                entry["val_score"] = float(np.mean(iou[list(SELECTION_CLASSES)]))
                if entry["val_score"] > best.score:
                    best = _Best(step, entry["val_score"], tuple(_or_none(v) for v in iou),
                                 {k: v.clone() for k, v in model.state_dict().items()})
            history.append(entry)
            bar.set_postfix(loss=f"{entry['loss']:.3f}",
                            val_window_iou=f"{entry.get('val_window_iou', float('nan')):.3f}",
                            val_score=f"{entry.get('val_score', float('nan')):.3f}")
        if over_time:
            tqdm.write(f"stopped after {step} of {config.steps} steps: the "
                       f"{config.max_minutes:g}-minute cap was reached (recorded as cut short)")
            break
    if not selection:
        best = _Best(step)
    return best, history, step


def _mixed_batch(renders: list[Source], real: list[Source], n_renders: int,
                 n_real: int, config: TrainConfig, rng: np.random.Generator
                 ) -> tuple[torch.Tensor, torch.Tensor]:
    """``n_renders`` render crops then ``n_real`` real-photo crops, one batch."""
    parts = [sample_batch(sources, n, config.augment, rng)
             for sources, n in ((renders, n_renders), (real, n_real)) if n > 0]
    x = torch.cat([p[0] for p in parts]).contiguous(memory_format=torch.channels_last)
    return x, torch.cat([p[1] for p in parts])


def validation_iou(model: UNet, val: Sequence[Source], frames: int,
              threads: int) -> np.ndarray:
    """(NUM_CLASSES,) IoU per class on the validation scenes (or real sources), pooled per
    scene, then the mean over scenes (NaN-aware). A render scene gives ``frames`` evenly
    spaced frames; a real source all its photos."""
    model.eval()
    ious = []
    for scene in val:
        confusion = np.zeros((NUM_CLASSES, NUM_CLASSES), np.int64)
        picked = scene.frames if isinstance(scene, RealSource) else evenly_spaced(
            scene.frames, frames)
        for frame in picked:
            rgb, exact = scene.rgb_and_labels(frame)
            confusion += confusion_matrix(predict_labels(model, rgb, threads=threads), exact)
        ious.append(iou_per_class(confusion))
    return mean_iou(np.array(ious))


def _or_none(value: float) -> float | None:
    """A JSON-ready IoU: ``None`` for a class absent from every validation scene."""
    return None if np.isnan(value) else float(value)


RENDERS_SOURCE = {
    "repository": "this project's procedural renders (the segtrain preset, dataset.presets)",
    "licence": "MIT (the project's own)",
}
"""What the render scenes a segmenter trains on are, for its record."""


def training_sets(real: Mapping[str, Path]) -> dict[str, dict[str, str]]:
    """Every set a training reads, with its source and licence: the renders, and each real
    set of ``real`` (set name -> folder; :data:`segment.real_sets.SOURCES`)."""
    return {"renders": dict(RENDERS_SOURCE), **{n: dict(SOURCES[n]) for n in sorted(real)}}


def _record(config: TrainConfig, train: Sequence[Source], val: Sequence[Source],
            weights: np.ndarray, best: _Best, history: list[dict[str, float]],
            steps_run: int, times: dict[str, float]) -> dict[str, Any]:
    return {
        "what": "segmenter weights: RGB -> class ids " + ", ".join(
            f"{i} {n}" for i, n in enumerate(CLASS_NAMES)),
        "trained_on": [s.record for s in train],
        "validated_on": [s.record for s in val],
        "config": asdict(config),
        "class_weights": [round(float(w), 4) for w in weights],
        "steps_run": steps_run,
        "cut_short": steps_run < config.steps,
        "best_step": best.step,
        "val_window_iou": best.iou[SemanticClass.WINDOW] if best.iou else None,
        "val_score": best.score if best.iou else None,
        "val_iou": dict(zip(CLASS_NAMES, best.iou)) if best.iou else None,
        "history": history,
        **times,  # CPU time: what the run costs on idle cores, whatever else ran beside it
        "threads": config.threads,
    }


def main(argv: Sequence[str] | None = None) -> int:
    d = TrainConfig()
    parser = argparse.ArgumentParser(
        prog="python -m segment.train",
        description="Train the mask segmenter (a compact U-Net, RGB -> background, wall, "
        "window, roof, door, other) on rendered buildings that are never evaluated, and write "
        "its weights with their training record. Scenes of an evaluated preset are refused.",
        epilog="example: python -m dataset.generate --preset segtrain --out data/segtrain-512 "
        "--views 40 && python -m segment.train --data data/segtrain-512 --out "
        "segment/weights/renders.pt. Details: docs/segment.md.",
    )
    parser.add_argument("--data", type=Path, action="append", required=True,
                        help="a folder of training scenes (repeat for several, e.g. the same "
                        "buildings rendered at two resolutions)")
    parser.add_argument("--out", type=Path, required=True, help="weights file to write (*.pt)")
    parser.add_argument("--steps", type=int, default=d.steps,
                        help=f"optimiser steps (default {d.steps})")
    parser.add_argument("--batch", type=int, default=d.batch,
                        help=f"crops per step (default {d.batch})")
    parser.add_argument("--crop", type=int, default=d.augment.crop_px,
                        help=f"crop side in pixels (default {d.augment.crop_px})")
    parser.add_argument("--learning-rate", type=float, default=d.learning_rate,
                        help=f"peak learning rate (default {d.learning_rate})")
    parser.add_argument("--seed", type=int, default=d.seed, help=f"seed (default {d.seed})")
    parser.add_argument("--threads", type=int, default=d.threads,
                        help=f"torch CPU threads (default {d.threads})")
    parser.add_argument("--val-every", type=int, default=d.val_every,
                        help=f"every N-th building validates instead of training; 0: none "
                        f"(default {d.val_every})")
    parser.add_argument("--validate-every", type=int, default=d.validate_every,
                        help=f"steps between validations (default {d.validate_every})")
    parser.add_argument("--max-minutes", type=float, default=d.max_minutes,
                        help=f"time cap; a run it stops is recorded as cut short "
                        f"(default {d.max_minutes:g})")
    for name in SET_NAMES:
        parser.add_argument(f"--{name}", type=Path,
                            help=f"a copy of the real set {name}: its train photos are trained "
                            f"on, its val photos pick the weights (docs/segment.md)")
    parser.add_argument("--real-share", type=float, default=d.real_share,
                        help=f"share of each batch from real photos when real sets are given "
                        f"(default {d.real_share})")
    n = d.network
    parser.add_argument("--base-channels", type=int, default=n.base_channels,
                        help=f"U-Net channels at its first scale (default {n.base_channels})")
    parser.add_argument("--levels", type=int, default=n.levels,
                        help=f"U-Net scales (default {n.levels})")
    parser.add_argument("--stem-stride", type=int, choices=(1, 2), default=n.stem_stride,
                        help="2: a strided stem halves the resolution first, the logits are "
                        f"upsampled (default {n.stem_stride})")
    parser.add_argument("--working-px", type=int, default=n.working_long_side_px,
                        help="scale every image to this long side, in training and when "
                        "segmenting (default: each image at its own size)")
    parser.add_argument("--render-frames", type=int, default=d.render_frames,
                        help="with --working-px: frames read per render building, evenly "
                        f"spaced (default {d.render_frames}: all)")
    parser.add_argument("--scale", type=float, nargs=2, metavar=("MIN", "MAX"),
                        help="range of the crops' random zoom (default "
                        f"{d.augment.scale[0]:g} {d.augment.scale[1]:g})")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    add_debug_flag(parser)
    args = parser.parse_args(argv)

    def body() -> int:
        if args.out.suffix != ".pt":
            raise ValueError(f"--out {args.out} must name a .pt file")
        check_output_folder(args.out.parent, "--out")
        real = {n: getattr(args, n) for n in SET_NAMES if getattr(args, n) is not None}
        augment = replace(REAL_PHOTO_AUGMENT if real else AugmentConfig(), crop_px=args.crop)
        if args.scale is not None:
            augment = replace(augment, scale=tuple(args.scale))
        network = UNetConfig(base_channels=args.base_channels, levels=args.levels,
                             stem_stride=args.stem_stride,
                             working_long_side_px=args.working_px)
        config = TrainConfig(
            steps=args.steps, batch=args.batch, learning_rate=args.learning_rate,
            seed=args.seed, threads=args.threads, val_every=args.val_every,
            validate_every=args.validate_every, max_minutes=args.max_minutes,
            real_share=args.real_share, render_frames=args.render_frames, network=network,
            augment=augment)
        record = train_segmenter(args.data, args.out, config, real=real or None,
                                 progress=not args.quiet)
        print(f"wrote {args.out} ({len(record['trained_on'])} training scenes, "
              f"{record['steps_run']} steps, {record['wall_time_s'] / 60:.1f} min); validation "
              f"window IoU {record['val_window_iou']}")
        return 0

    return run_cli("segment.train", body, debug=args.debug,
                   interrupted="interrupted: no weights written")


if __name__ == "__main__":
    exit_cli(main())
