"""How well masks agree with the exact ones: per-class IoU per building, and the CLI.

``python -m segment.evaluate --data DIR [--model default|FILE.pt|PLUGIN]`` runs a
segmenter on every scene of ``DIR`` (or an evenly spaced subset of each scene's frames)
and prints, per building and per family, the IoU of each class against the scene's
exact masks, pooled over the frames (intersection and union summed before dividing).
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TypeVar

import numpy as np
from tqdm import tqdm

from envelope.atomic import write_text_atomic
from envelope.classes import CLASS_NAMES, NUM_CLASSES, SemanticClass
from envelope.cli_errors import add_debug_flag, exit_cli, run_cli
from envelope.photo_io import read_photo_rgb
from envelope.scene_record import Scene
from envelope.scenes.scene import find_scene_folders, read_scene
from envelope.scenes.scene_validation import read_frame_labels
from segment.segmenter import Segmenter, resolve_segmenter, segment_rgb

T = TypeVar("T")


def confusion_matrix(predicted: np.ndarray, exact: np.ndarray) -> np.ndarray:
    """(NUM_CLASSES, NUM_CLASSES) int64 pixel counts, row = exact class, column = predicted.

    Parameters
    ----------
    predicted, exact : (H, W) integer class ids (ids >= NUM_CLASSES are not counted)
    """
    if predicted.shape != exact.shape:
        raise ValueError(f"masks of different shapes: {predicted.shape} vs {exact.shape}")
    p, e = predicted.ravel().astype(np.int64), exact.ravel().astype(np.int64)
    keep = (p < NUM_CLASSES) & (e < NUM_CLASSES)
    return np.bincount(e[keep] * NUM_CLASSES + p[keep],
                       minlength=NUM_CLASSES**2).reshape(NUM_CLASSES, NUM_CLASSES)


def iou_per_class(confusion: np.ndarray) -> np.ndarray:
    """(NUM_CLASSES,) IoU of each class from a confusion matrix; NaN for a class absent from
    both masks."""
    tp = np.diag(confusion).astype(np.float64)
    union = confusion.sum(axis=0) + confusion.sum(axis=1) - tp
    return np.divide(tp, union, out=np.full(len(tp), np.nan), where=union > 0)


def mean_iou(ious: np.ndarray) -> np.ndarray:
    """(C,) mean over scenes of (N, C) per-scene IoUs, skipping NaN; NaN where all are."""
    ious = np.asarray(ious, dtype=np.float64).reshape(-1, NUM_CLASSES)
    seen = ~np.isnan(ious)
    total = np.where(seen, ious, 0.0).sum(axis=0)
    return np.divide(total, seen.sum(axis=0), out=np.full(NUM_CLASSES, np.nan),
                     where=seen.any(axis=0))


@dataclass(frozen=True)
class SceneIou:
    """One building's pooled confusion matrix over ``frames`` frames, and its family."""

    scene: str
    family: str
    frames: int
    confusion: np.ndarray

    @property
    def iou(self) -> np.ndarray:
        return iou_per_class(self.confusion)

    @property
    def window_iou(self) -> float:
        return float(self.iou[SemanticClass.WINDOW])


def evenly_spaced(items: Sequence[T], max_items: int | None) -> tuple[T, ...]:
    """At most ``max_items`` of ``items`` (frames, say), evenly spaced (all for ``None``)."""
    if max_items is None or len(items) <= max_items:
        return tuple(items)
    picks = np.linspace(0, len(items) - 1, max_items).round().astype(int)
    return tuple(items[i] for i in sorted(set(picks)))


def segmenter_scene_iou(scene: Scene, segmenter: Segmenter,
                        max_frames: int | None = None) -> SceneIou:
    """IoU of ``segmenter``'s masks against ``scene``'s exact masks (frames with one)."""
    frames = evenly_spaced([f for f in scene.frames if f.semantic_file_path], max_frames)
    confusion = np.zeros((NUM_CLASSES, NUM_CLASSES), np.int64)
    for fr in frames:
        labels = segment_rgb(segmenter, read_photo_rgb(scene.path(fr.file_path)))
        confusion += confusion_matrix(labels, read_frame_labels(scene, fr))
    return SceneIou(scene.root.name, _family(scene), len(frames), confusion)


def masks_scene_iou(exact: Scene, predicted: Scene) -> SceneIou:
    """IoU of a mask copy's semantic images against the exact scene's, over the copy's
    frames (matched by image path; a copy may hold only some of the scene's frames)."""
    confusion = np.zeros((NUM_CLASSES, NUM_CLASSES), np.int64)
    count = 0
    exact_frames = {f.file_path: f for f in exact.frames}
    for fp in predicted.frames:
        fe = exact_frames.get(fp.file_path)
        if fe is None or fe.semantic_file_path is None or fp.semantic_file_path is None:
            continue
        confusion += confusion_matrix(read_frame_labels(predicted, fp),
                                      read_frame_labels(exact, fe))
        count += 1
    return SceneIou(exact.root.name, _family(exact), count, confusion)


def iou_table(rows: Sequence[SceneIou]) -> str:
    """CSV text: one line per building, then one per family (mean over its buildings)."""
    names = [f"{n}_iou" for n in CLASS_NAMES]
    lines = ["scene,family,frames," + ",".join(names)]
    for r in rows:
        lines.append(f"{r.scene},{r.family},{r.frames}," + ",".join(_f(v) for v in r.iou))
    for family in sorted({r.family for r in rows}):
        group = np.array([r.iou for r in rows if r.family == family])
        lines.append(f"mean,{family},{len(group)}," + ",".join(_f(v) for v in mean_iou(group)))
    return "\n".join(lines) + "\n"


def _f(value: float) -> str:
    return "" if np.isnan(value) else f"{value:.4f}"


def _family(scene: Scene) -> str:
    return scene.building.type if scene.building is not None else "unknown"


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m segment.evaluate",
        description="Run a segmenter on the RGB images of scenes and print the IoU of each "
        "class against the scenes' exact masks, per building and per family (pooled over "
        "each building's frames). Run it on buildings the segmenter was not trained on.",
        epilog="example: python -m segment.evaluate --data data/paper --max-frames 40",
    )
    parser.add_argument("--data", type=Path, required=True,
                        help="a scene folder or a folder of scene folders")
    parser.add_argument("--model", default=None,
                        help="'default' (the committed weights), a weights file (*.pt) or an "
                        "installed segmenter plugin's name (default: default)")
    parser.add_argument("--max-frames", type=int, default=None,
                        help="evenly spaced frames per building (default: all)")
    parser.add_argument("--threads", type=int, default=2, help="torch threads (default: 2)")
    parser.add_argument("--csv", type=Path, help="also write the table to this CSV file")
    add_debug_flag(parser)
    args = parser.parse_args(argv)

    def body() -> int:
        if args.max_frames is not None and args.max_frames < 1:
            raise ValueError(f"--max-frames must be >= 1, got {args.max_frames}")
        segmenter = resolve_segmenter(args.model, threads=args.threads)
        dirs = find_scene_folders(args.data, with_images=True)
        rows = [segmenter_scene_iou(read_scene(d), segmenter, args.max_frames)
                for d in tqdm(dirs, desc="segment", unit="building")]
        text = iou_table(rows)
        if args.csv is not None:
            write_text_atomic(args.csv, f"# python -m segment.evaluate, model "
                              f"{segmenter.name}\n" + text)
        print(text, end="")
        return 0

    return run_cli("segment.evaluate", body, debug=args.debug)


if __name__ == "__main__":
    exit_cli(main())
