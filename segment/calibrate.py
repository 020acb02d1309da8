"""Calibrate a segmenter's window area on its validation buildings, and the CLI.

A network trained for per-pixel accuracy can still call too many pixels window (frames
and reveals bleed into the glass): its window IoU is high while every window *area* it
gives is too large, and a WWR method reading its masks inherits that bias in full. The
calibration adds one offset ``delta`` to the window logit before the arg-max, chosen so
that on the validation buildings the predicted window pixels number as many as the exact
ones. A pixel is window after the offset iff its margin ``window logit - max(other
logits)`` exceeds ``-delta``, so one histogram of the margins over all pixels (and one over
the exact window pixels) gives the area and IoU of every offset at once.

``python -m segment.calibrate --data DIR [DIR ...]`` reads the validation buildings that
the weights' record names (never evaluated, never trained on), writes the offsets into
the weights file (``record["calibration"]``) and prints the window area ratio and IoU
before and after. Weights picked on real validation photos (trained with real sets) are
calibrated on those same photos instead (``--labelmefacade DIR``, ``--cmp DIR``); pixels
their labels do not count are left out.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import torch
from tqdm import tqdm

from envelope.classes import NUM_CLASSES, SemanticClass
from envelope.cli_errors import add_debug_flag, exit_cli, run_cli
from segment.augment import IGNORE_LABEL
from segment.evaluate import evenly_spaced
from segment.network import UNet
from segment.real_sets import SET_NAMES
from segment.real_training import RealSource, real_sources
from segment.segmenter import predict_logits
from segment.training_data import TrainingScene, load_training_scenes
from segment.weights import RENDER_WEIGHTS, load_network, save_weights

MARGIN_EDGES = np.linspace(-40.0, 40.0, 3201)
"""Histogram bin edges of the window logit margin (0.025 wide; margins beyond are clipped)."""


@dataclass(frozen=True)
class WindowCalibration:
    """The window logit offset and what it does on the validation frames.

    ``area_ratio``: predicted / exact window pixels; ``iou``: window IoU; each before
    (offset 0) and after (offset ``window_offset``)."""

    window_offset: float
    area_ratio_before: float
    area_ratio_after: float
    iou_before: float
    iou_after: float
    frames: int
    scenes: tuple[str, ...]

    def logit_offsets(self) -> list[float]:
        """(NUM_CLASSES,) offsets added to the logits: the window's, 0 for the others."""
        offsets = [0.0] * NUM_CLASSES
        offsets[SemanticClass.WINDOW] = self.window_offset
        return offsets


def window_margin(model: UNet, rgb: np.ndarray, threads: int) -> np.ndarray:
    """(H, W) float32 ``window logit - max(other logits)`` of a (H, W, 3) uint8 image."""
    logits = predict_logits(model, rgb, threads=threads)
    w = SemanticClass.WINDOW
    others = torch.cat([logits[:w], logits[w + 1:]])
    return (logits[w] - others.max(0).values).numpy()


Validation = TrainingScene | RealSource


def margin_histograms(model: UNet, scenes: Sequence[Validation], frames: int,
                      threads: int, progress: bool = False) -> tuple[np.ndarray, np.ndarray, int]:
    """(counted pixels, exact window pixels) histograms of the margin over ``MARGIN_EDGES``,
    and the number of frames read (``frames`` evenly spaced ones per scene or set of photos);
    a pixel labelled :data:`IGNORE_LABEL` is not counted."""
    every = np.zeros(len(MARGIN_EDGES) - 1, np.int64)
    window = np.zeros_like(every)
    pairs = [(s, f) for s in scenes for f in evenly_spaced(s.frames, frames)]
    for scene, frame in tqdm(pairs, desc="calibrate", unit="frame", disable=not progress):
        rgb, exact = scene.rgb_and_labels(frame)
        margin = np.clip(window_margin(model, rgb, threads), MARGIN_EDGES[0], MARGIN_EDGES[-1])
        every += np.histogram(margin[exact != IGNORE_LABEL], MARGIN_EDGES)[0]
        window += np.histogram(margin[exact == SemanticClass.WINDOW], MARGIN_EDGES)[0]
    return every, window, len(pairs)


def area_and_iou(every: np.ndarray, window: np.ndarray, offset: float) -> tuple[float, float]:
    """Window area ratio (predicted / exact) and IoU at ``offset``, from the histograms
    (a bin counts as window when its upper edge exceeds ``-offset``)."""
    on = MARGIN_EDGES[1:] > -offset
    predicted, exact, hit = every[on].sum(), window.sum(), window[on].sum()
    if exact == 0:
        raise ValueError("the validation frames show no window; calibrate on buildings with "
                         "windows")
    return float(predicted / exact), float(hit / (exact + predicted - hit))


def unbiased_offset(every: np.ndarray, window: np.ndarray) -> float:
    """The offset (a bin edge, negated) whose predicted window pixels are closest in number
    to the exact ones."""
    # predicted(offset = -edge) = pixels with margin above edge: a cumulative sum from the top
    above = np.concatenate([np.cumsum(every[::-1])[::-1], [0]])
    best = int(np.argmin(np.abs(above - window.sum())))
    return float(-MARGIN_EDGES[best]) + 0.0  # + 0.0: 0.0 rather than -0.0 at the middle edge


def calibrate_window(model: UNet, scenes: Sequence[Validation], frames: int = 24,
                     threads: int = 2, progress: bool = False) -> WindowCalibration:
    """The window offset that makes the window area unbiased on ``scenes``."""
    every, window, read = margin_histograms(model, scenes, frames, threads, progress)
    offset = unbiased_offset(every, window)
    ratio0, iou0 = area_and_iou(every, window, 0.0)
    ratio1, iou1 = area_and_iou(every, window, offset)
    return WindowCalibration(offset, ratio0, ratio1, iou0, iou1, read,
                             tuple(sorted(f"{s.record['folder']}/{s.name}" for s in scenes)))


def validation_scenes(record: dict[str, Any], folders: Sequence[Path],
                      real: dict[str, Path] | None = None) -> list[Validation]:
    """What ``record["validated_on"]`` names: the validation buildings (by name and
    resolution) read from ``folders``, each carrying its entry of the record, so a
    calibration names them as the training did wherever they are read from; or, for weights
    picked on real photos, the same validation photos read from ``real`` (set name ->
    folder, :mod:`segment.real_training`).

    Raises
    ------
    ValueError
        If the record names no validation building or none of them is in ``folders``, or
        the weights were picked on real photos whose sets ``real`` lacks or whose copy
        holds other validation photos than the record names.
    """
    validated = record.get("validated_on") or []
    photos = [v for v in validated if "set" in v]
    if photos:
        return _validation_photos(photos, real or {})
    wanted = {(v["scene"], v.get("resolution")): v for v in validated}
    if not wanted:
        raise ValueError("these weights record no validation buildings to calibrate on; "
                         "train them with `python -m segment.train` (it keeps every "
                         "--val-every-th building for validation)")
    found = [replace(s, record=wanted[(s.name, s.record["resolution"])])
             for s in load_training_scenes(folders)
             if (s.name, s.record["resolution"]) in wanted]
    if not found:
        raise ValueError(f"none of the validation buildings "
                         f"{sorted({name for name, _ in wanted})} is in "
                         f"{', '.join(map(str, folders))}; render them with `python -m "
                         f"dataset.generate --preset segtrain --out DIR` (docs/segment.md)")
    return found


def _validation_photos(validated: list[dict[str, Any]], real: dict[str, Path]
                       ) -> list[RealSource]:
    """The real validation photos of ``validated`` (entries of a weights record), checked
    to be the very photos the record names."""
    missing = [v["set"] for v in validated if v["set"] not in real]
    if missing:
        raise ValueError(f"these weights were picked on real validation photos; calibrate "
                         f"them on the same photos: give --{missing[0]} DIR (a copy of "
                         f"that set, docs/segment.md)")
    roots = {v["set"]: real[v["set"]] for v in validated}
    _, sources = real_sources(roots, val_photos=max(v["photos"] for v in validated))
    read = {s.set_name: [p.name for p in s.frames] for s in sources}
    for entry in validated:
        if read.get(entry["set"]) != entry["names"]:
            raise ValueError(f"{roots[entry['set']]} does not hold the validation photos the "
                             f"weights' record names for {entry['set']}; give the copy they "
                             f"were trained with")
    return sources


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m segment.calibrate",
        description="Choose the window logit offset that makes a segmenter's window area "
        "unbiased on its validation buildings (never evaluated), or on its validation photos "
        "when it was picked on real photos, and write it into the weights file.",
        epilog="example: python -m segment.calibrate --data data/segtrain-128 --data "
        "data/segtrain-512. Details: docs/segment.md.")
    parser.add_argument("--data", type=Path, action="append", default=[],
                        help="a folder holding the validation buildings (repeat for several)")
    for name in SET_NAMES:
        parser.add_argument(f"--{name}", type=Path,
                            help=f"a copy of the real set {name}, for weights picked on its "
                            f"validation photos")
    parser.add_argument("--weights", type=Path, default=RENDER_WEIGHTS,
                        help="weights file to calibrate (default: the committed render-trained "
                        "weights)")
    parser.add_argument("--out", type=Path, default=None,
                        help="where to write the calibrated weights (default: --weights)")
    parser.add_argument("--frames", type=int, default=24,
                        help="evenly spaced frames per building (default 24)")
    parser.add_argument("--threads", type=int, default=2, help="torch threads (default 2)")
    add_debug_flag(parser)
    args = parser.parse_args(argv)

    def body() -> int:
        if args.frames < 1 or args.threads < 1:
            raise ValueError("--frames and --threads must be >= 1")
        model, record = load_network(args.weights)
        real = {n: getattr(args, n) for n in SET_NAMES if getattr(args, n) is not None}
        scenes = validation_scenes(record, args.data, real)
        result = calibrate_window(model, scenes, args.frames, args.threads, progress=True)
        record = {**record, "calibration": {**asdict(result),
                                            "logit_offsets": result.logit_offsets()}}
        out = args.out or args.weights
        save_weights(out, model, record)
        print(f"window offset {result.window_offset:+.3f} on {result.frames} frames of "
              f"{len(scenes)} validation sources: window area ratio "
              f"{result.area_ratio_before:.3f} -> {result.area_ratio_after:.3f}, window IoU "
              f"{result.iou_before:.3f} -> {result.iou_after:.3f}; wrote {out}")
        return 0

    return run_cli("segment.calibrate", body, debug=args.debug,
                   interrupted="interrupted: the weights file is unchanged")


if __name__ == "__main__":
    exit_cli(main())
