"""``python -m segment.evaluate_real``: a segmenter on labelled real photos, written as a
Markdown report (docs/measurements/segment-real-photos.md).

Reads the copies of LabelMeFacade and the CMP Facade Database the user points at
(:mod:`segment.real_sets`), takes each photo's split from the committed lists
(:mod:`segment.real_sets.splits`; photos of no split are skipped), segments every photo
once at its own size and writes the figures of :mod:`segment.real_measure` per set and
split: window IoU, precision and recall, and on the rectified CMP facades the WWR error
of a 2D-S-style ratio. Nothing is tuned here.
"""

from __future__ import annotations

import argparse
import shlex
import sys
import time
from collections.abc import Sequence
from datetime import datetime, timezone
from pathlib import Path

import numpy as np
from tqdm import tqdm

from envelope.atomic import write_text_atomic
from envelope.classes import CLASS_NAMES
from envelope.cli_errors import add_debug_flag, exit_cli, run_cli
from envelope.provenance import code_version
from segment.evaluate import evenly_spaced
from segment.real_measure import (
    WWR_BANDS_POINTS,
    PhotoResult,
    mean_labels_wwr,
    photo_result,
    photo_rows_csv,
    predicted_as,
    split_scores,
    wwr_scores,
)
from segment.real_sets import SET_NAMES, SOURCES, RealPhoto, cmp, read_set
from segment.real_sets.common import PHOTO_SPLITS, PHOTO_TEST, PHOTO_TRAIN, PHOTO_VAL
from segment.real_sets.splits import committed_splits, split_of
from segment.segmenter import Segmenter, resolve_segmenter

REPORT_SPLITS = (PHOTO_TEST, PHOTO_VAL, PHOTO_TRAIN)
"""Order of the splits in the report."""


def evaluate_set(photos: Sequence[RealPhoto], segmenter: Segmenter,
                 max_photos: int | None = None, splits: Sequence[str] = REPORT_SPLITS
                 ) -> dict[str, list[PhotoResult]]:
    """Results per split (:data:`REPORT_SPLITS` order) of a set's photos; at most
    ``max_photos`` evenly spaced photos per split (all for ``None``); the photos of a split
    not in ``splits`` are not read (an empty list)."""
    committed = committed_splits(photos[0].set_name) if photos else {}
    by_split: dict[str, list[RealPhoto]] = {s: [] for s in REPORT_SPLITS}
    for photo in photos:
        split = split_of(photo, committed)
        if split in PHOTO_SPLITS:
            by_split[split].append(photo)
    out = {}
    for split in REPORT_SPLITS:
        chosen = evenly_spaced(by_split[split], max_photos) if split in splits else ()
        out[split] = [photo_result(p, split, segmenter)
                      for p in tqdm(chosen, desc=f"{photos[0].set_name} {split}",
                                    unit="photo")] if chosen else []
    return out


def report_markdown(results: dict[str, dict[str, list[PhotoResult]]], segmenter: Segmenter,
                    command: str, roots: dict[str, Path], seconds: tuple[float, float],
                    threads: int, started: tuple[str, str]) -> str:
    """The Markdown report of :func:`evaluate_set` results of each set (module doc);
    ``started`` is (UTC time, code version) at the start of the run."""
    wall_s, cpu_s = seconds
    when, code = started
    ident = ", ".join(f"{k} {v}" for k, v in segmenter.identity.items())
    lines = [
        "# The segmenter on labelled real photos", "",
        "Written by:", "", "```bash", command, "```", "",
        f"{when}, code `{code}`, segmenter `{segmenter.name}` ({ident}); "
        f"{threads} torch thread(s), {wall_s:.0f} s wall, {cpu_s:.0f} s CPU. Each photo is "
        f"segmented once (at the network's working size if it has one, the answer scaled "
        f"back to the photo's size); its split comes from the committed lists "
        f"(`segment/real_sets/splits/`); nothing is tuned on these photos. Definitions: "
        f"docs/segment.md, \"Real labelled facades\".", "",
        "| set | copy read (source, commit) | licence |", "|---|---|---|",
    ]
    for name in results:
        src = SOURCES[name]
        lines.append(f"| {name} | {roots[name].name}/ ({src['repository']}, "
                     f"`{src['commit'][:12]}`) | {src['licence']} |")
    lines += ["", "## Window masks per split", "",
              "Window IoU pooled over the split's photos (intersection and union summed "
              "first) and its mean over the photos with windows; precision: predicted window "
              "pixels that are window; recall: window pixels predicted window.", "",
              "| set | split | photos | window IoU | window IoU, mean over photos "
              "(with windows) | window precision | window recall | wall IoU | "
              "background IoU |", "|---|---|---|---|---|---|---|---|---|"]
    for name, per_split in results.items():
        for split, rows in per_split.items():
            if not rows:
                continue
            s = split_scores(rows)
            lines.append(f"| {name} | {split} | {s.photos} | **{s.window_iou:.3f}** | "
                         f"{s.window_iou_mean:.3f} ({s.photos_with_windows}) | "
                         f"{s.window_precision:.3f} | {s.window_recall:.3f} | "
                         f"{s.wall_iou:.3f} | {s.background_iou:.3f} |")
    if cmp.SET_NAME in results:
        bands = " | ".join(f"within ±{b:g}" for b in WWR_BANDS_POINTS)
        lines += ["", "## WWR on the rectified CMP facades", "",
                  "A 2D-S-style ratio, window / (wall + window + door) pixels, of the "
                  "predicted mask against the same ratio of the labels, over the pixels the "
                  "labels count; error in percentage points (answer minus labels). Beside "
                  "it, a constant answer for every facade: the mean WWR of the train "
                  "split's labels (what a ratio reading nothing of the photo achieves).", "",
                  f"| split | answer | facades | labels' WWR, mean | answer's WWR, mean | "
                  f"mean absolute error (points) | mean error (points) | {bands} |",
                  "|---|---|---|---|---|---|---|" + "---|" * len(WWR_BANDS_POINTS)]
        constant = mean_labels_wwr(results[cmp.SET_NAME].get(PHOTO_TRAIN) or [])
        for split, rows in results[cmp.SET_NAME].items():
            if not rows:
                continue
            answers = [("predicted masks", wwr_scores(rows))]
            if np.isfinite(constant):
                answers.append((f"constant {constant:.3f}", wwr_scores(rows, constant)))
            for what, w in answers:
                shares = " | ".join(f"{w.within_points[b]:.0%}" for b in WWR_BANDS_POINTS)
                lines.append(f"| {split} | {what} | {w.facades} | {w.labels_mean:.3f} | "
                             f"{w.predicted_mean:.3f} | **{w.mean_abs_error_points:.1f}** | "
                             f"{w.mean_error_points:+.1f} | {shares} |")
    lines += ["", "## What the labels' window pixels are predicted as", "",
              "| set | split | " + " | ".join(CLASS_NAMES) + " |",
              "|---|---|" + "---|" * len(CLASS_NAMES)]
    for name, per_split in results.items():
        for split, rows in per_split.items():
            if rows:
                lines.append(f"| {name} | {split} | " + " | ".join(
                    f"{v:.2f}" for v in predicted_as(rows)) + " |")
    return "\n".join(lines) + "\n"


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m segment.evaluate_real",
        description="Run a segmenter on labelled real photos (LabelMeFacade, CMP Facade "
        "Database; copies you point at) and write window IoU, precision and recall per "
        "split, and the WWR error on the rectified CMP facades, as Markdown.",
        epilog="example: python -m segment.evaluate_real --labelmefacade ~/labelmefacade "
        "--cmp ~/CMP_facade_DB --out docs/measurements/segment-real-photos.md",
    )
    parser.add_argument("--labelmefacade", type=Path,
                        help="a clone of github.com/cvjena/labelmefacade")
    parser.add_argument("--cmp", type=Path,
                        help="a CMP Facade Database folder (base/ and/or extended/)")
    parser.add_argument("--out", type=Path, required=True, help="the Markdown file to write")
    parser.add_argument("--model", default=None,
                        help="'default', a weights file (*.pt) or a segmenter plugin "
                        "(default: default)")
    parser.add_argument("--csv", type=Path,
                        help="also write one line per photo (window IoU, precision, recall, "
                        "WWR of the labels and of the prediction) to this CSV file")
    parser.add_argument("--max-photos", type=int, default=None,
                        help="evenly spaced photos per set and split (default: all)")
    parser.add_argument("--splits", nargs="+", choices=REPORT_SPLITS, default=REPORT_SPLITS,
                        help="the splits to read (default: all); e.g. `--splits val` to "
                        "choose between segmenters without reading a test photo")
    parser.add_argument("--threads", type=int, default=2, help="torch threads (default: 2)")
    add_debug_flag(parser)
    args = parser.parse_args(argv)

    def body() -> int:
        roots = {n: getattr(args, n) for n in SET_NAMES if getattr(args, n) is not None}
        if not roots:
            raise ValueError("give --labelmefacade and/or --cmp: folders of the sets")
        if args.max_photos is not None and args.max_photos < 1:
            raise ValueError(f"--max-photos must be >= 1, got {args.max_photos}")
        sets = {name: read_set(name, root) for name, root in roots.items()}
        segmenter = resolve_segmenter(args.model, threads=args.threads)
        started = (datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC"), code_version())
        start_wall, start_cpu = time.perf_counter(), time.process_time()
        results = {name: evaluate_set(photos, segmenter, args.max_photos, args.splits)
                   for name, photos in sets.items()}
        seconds = (time.perf_counter() - start_wall, time.process_time() - start_cpu)
        command = "python -m segment.evaluate_real " + shlex.join(
            sys.argv[1:] if argv is None else list(argv))
        text = report_markdown(results, segmenter, command, roots, seconds, args.threads,
                               started)
        write_text_atomic(args.out, text)
        if args.csv is not None:
            write_text_atomic(args.csv, photo_rows_csv(results))
        print(text, end="")
        return 0

    return run_cli("segment.evaluate_real", body, debug=args.debug)


if __name__ == "__main__":
    exit_cli(main())
