"""What a segmenter's masks are worth on labelled real photos: window IoU, precision and
recall per split, and the WWR a 2D-S-style ratio gives on the rectified CMP facades.

Per photo (:func:`photo_result`): the photo is segmented at its own size and compared
with its labels mapped to the project's classes (:mod:`segment.real_sets`); pixels the
labels do not count (:data:`segment.real_sets.IGNORED`) count nowhere. Per split
(:func:`split_scores`): the window IoU pooled over the photos (intersection and union
summed first), its mean over the photos that have windows, the window precision
(predicted window pixels that are window) and recall (window pixels predicted window),
and the wall and background IoU.

WWR (:func:`facade_wwr`): window pixels / (wall + window + door pixels) of a mask, the
ratio 2D-S takes on a rectified facade view, over the pixels the labels count (both
masks over the same pixels: a shop front, unlabelled by the project's classes, is out of
both). On the CMP facades, which are rectified, the ratio of the predicted mask is
compared with the ratio of the labels: the error in percentage points per facade, its
mean absolute value and mean, and the share of facades within 5 and 10 points; beside it
the same errors of a constant answer, the mean WWR of the train split's labels, for every
facade: what a ratio that reads nothing of the photo achieves.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from envelope.classes import NUM_CLASSES, SemanticClass
from segment.evaluate import confusion_matrix, iou_per_class
from segment.real_sets import IGNORED, RealPhoto, read_photo_pair
from segment.segmenter import Segmenter, segment_rgb

WINDOW, WALL, DOOR = SemanticClass.WINDOW, SemanticClass.WALL, SemanticClass.DOOR
WWR_BANDS_POINTS = (5.0, 10.0)
"""Error bands (percentage points of WWR) whose share of facades is reported."""


@dataclass(frozen=True)
class PhotoResult:
    """One photo's pooled-able counts: ``confusion`` (NUM_CLASSES, NUM_CLASSES), row =
    label class, column = predicted; WWR of the labels and of the prediction (NaN for a
    photo without facade pixels)."""

    name: str
    split: str
    confusion: np.ndarray
    wwr_labels: float
    wwr_predicted: float


@dataclass(frozen=True)
class SplitScores:
    """A split's figures (module doc); NaN where a figure has no pixel to count."""

    photos: int
    window_iou: float
    window_iou_mean: float
    photos_with_windows: int
    window_precision: float
    window_recall: float
    wall_iou: float
    background_iou: float


@dataclass(frozen=True)
class WwrScores:
    """WWR of the predicted masks against the labels' over ``facades`` facades (points)."""

    facades: int
    labels_mean: float
    predicted_mean: float
    mean_abs_error_points: float
    mean_error_points: float
    within_points: dict[float, float]


def facade_wwr(labels: np.ndarray) -> float:
    """window / (wall + window + door) pixels of (N,) or (H, W) class ids; NaN if none."""
    counts = np.bincount(labels.ravel(), minlength=NUM_CLASSES)
    facade = counts[WALL] + counts[WINDOW] + counts[DOOR]
    return float(counts[WINDOW] / facade) if facade > 0 else float("nan")


def photo_result(photo: RealPhoto, split: str, segmenter: Segmenter) -> PhotoResult:
    """Segment one labelled photo and count it (module doc)."""
    rgb, labels = read_photo_pair(photo)
    predicted = segment_rgb(segmenter, rgb)
    counted = labels != IGNORED
    return PhotoResult(photo.name, split, confusion_matrix(predicted, labels),
                       facade_wwr(labels[counted]), facade_wwr(predicted[counted]))


def window_precision_recall(confusion: np.ndarray) -> tuple[float, float]:
    """(precision, recall) of the window class from a confusion matrix (row = label)."""
    tp = float(confusion[WINDOW, WINDOW])
    predicted, actual = confusion[:, WINDOW].sum(), confusion[WINDOW].sum()
    return (tp / predicted if predicted else float("nan"),
            tp / actual if actual else float("nan"))


def split_scores(results: Sequence[PhotoResult]) -> SplitScores:
    """Pooled and per-photo window figures of a split's photos."""
    pooled = sum((r.confusion for r in results), np.zeros((NUM_CLASSES, NUM_CLASSES),
                                                           np.int64))
    iou = iou_per_class(pooled)
    per_photo = [iou_per_class(r.confusion)[WINDOW] for r in results
                 if r.confusion[WINDOW].sum() > 0]
    precision, recall = window_precision_recall(pooled)
    return SplitScores(len(results), float(iou[WINDOW]),
                       float(np.mean(per_photo)) if per_photo else float("nan"),
                       len(per_photo), precision, recall, float(iou[WALL]),
                       float(iou[SemanticClass.BACKGROUND]))


def wwr_scores(results: Sequence[PhotoResult], constant: float | None = None) -> WwrScores:
    """WWR errors over the photos where both the labels' and the answer's ratio exist (a
    predicted mask without facade pixels has none); the answer is the predicted masks'
    ratio, or with ``constant`` that one WWR for every photo (a reference that reads
    nothing of the photo)."""
    answer = [r.wwr_predicted if constant is None else constant for r in results]
    pairs = np.array([(r.wwr_labels, a) for r, a in zip(results, answer)
                      if np.isfinite(r.wwr_labels) and np.isfinite(a)]).reshape(-1, 2)
    if len(pairs) == 0:
        nan = float("nan")
        return WwrScores(0, nan, nan, nan, nan, {b: nan for b in WWR_BANDS_POINTS})
    error = (pairs[:, 1] - pairs[:, 0]) * 100.0
    return WwrScores(len(pairs), float(pairs[:, 0].mean()), float(pairs[:, 1].mean()),
                     float(np.abs(error).mean()), float(error.mean()),
                     {b: float(np.mean(np.abs(error) <= b)) for b in WWR_BANDS_POINTS})


def predicted_as(results: Sequence[PhotoResult]) -> np.ndarray:
    """(NUM_CLASSES,) share of the label-window pixels predicted as each class."""
    row = sum(r.confusion[WINDOW] for r in results)
    total = row.sum() if len(results) else 0
    return row / total if total else np.full(NUM_CLASSES, np.nan)


def mean_labels_wwr(results: Sequence[PhotoResult]) -> float:
    """Mean of the labels' WWR over the photos that have one (NaN if none)."""
    values = [r.wwr_labels for r in results if np.isfinite(r.wwr_labels)]
    return float(np.mean(values)) if values else float("nan")


def photo_rows_csv(results: dict[str, dict[str, list[PhotoResult]]]) -> str:
    """CSV text, one line per photo: set, split, name, window IoU, precision, recall, and
    the labels' and the predicted WWR (empty where undefined)."""
    lines = ["set,split,name,window_iou,window_precision,window_recall,wwr_labels,"
             "wwr_predicted"]
    for set_name, per_split in results.items():
        for split, rows in per_split.items():
            for r in rows:
                iou = iou_per_class(r.confusion)[WINDOW]
                precision, recall = window_precision_recall(r.confusion)
                values = (iou, precision, recall, r.wwr_labels, r.wwr_predicted)
                lines.append(f"{set_name},{split},{r.name}," + ",".join(
                    "" if np.isnan(v) else f"{v:.4f}" for v in values))
    return "\n".join(lines) + "\n"
