"""The segmenter's speed and size: images per second at 512 x 512 on the CPU; prints a
Markdown table.

    python bench/segment_speed.py [--weights NAME_OR_PATH ...] [--threads 2] [--images 20]

Segments ``--images`` images of 512 x 512 (a fixed random photo-like pattern: smooth colour
blobs and noise, the same for every weights file) with each weights file through
:func:`segment.segmenter.network_segmenter` (what ``--masks predicted`` runs: scaling to the
working size, the network, the calibration, the arg-max), after one warm-up image, and
prints per weights: its file size, parameters, working size, seconds per image and images
per second. The issue's bar (issue 45): >= 5 images/s at 512 x 512 on 2 cores, <= 20 MB.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import cv2
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench.tables import markdown_table  # noqa: E402
from segment.segmenter import network_segmenter  # noqa: E402
from segment.weights import BUILT_IN_WEIGHTS, load_network  # noqa: E402

COLUMNS = ("weights", "file MB", "parameters (M)", "working long side px", "threads",
           "s / image", "images / s")


def test_image(side_px: int = 512, seed: int = 0) -> np.ndarray:
    """(side, side, 3) uint8: blurred colour blobs plus noise, a stand-in for a photo."""
    rng = np.random.default_rng(seed)
    blobs = cv2.resize(rng.integers(0, 256, (16, 16, 3)).astype(np.uint8), (side_px, side_px),
                       interpolation=cv2.INTER_CUBIC)
    noise = rng.normal(0, 12, (side_px, side_px, 3))
    return np.clip(blobs + noise, 0, 255).astype(np.uint8)


def speed_row(weights: Path, threads: int, images: int) -> list[object]:
    model, _ = load_network(weights)
    segment = network_segmenter(weights, threads=threads).segment
    image = test_image()
    segment(image)  # warm-up: allocator and kernels
    tic = time.perf_counter()
    for _ in range(images):
        segment(image)
    per_image = (time.perf_counter() - tic) / images
    return [weights.name, f"{weights.stat().st_size / 1e6:.1f}",
            f"{sum(p.numel() for p in model.parameters()) / 1e6:.2f}",
            model.config.working_long_side_px or "own size", threads,
            f"{per_image:.3f}", f"{1 / per_image:.1f}"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--weights", nargs="+", default=sorted(BUILT_IN_WEIGHTS),
                        help="built-in names or weights files (default: every built-in)")
    parser.add_argument("--threads", type=int, default=2, help="torch threads (default 2)")
    parser.add_argument("--images", type=int, default=20,
                        help="images timed per weights file (default 20)")
    args = parser.parse_args()
    rows = [speed_row(Path(BUILT_IN_WEIGHTS.get(w, w)), args.threads, args.images)
            for w in args.weights]
    print(markdown_table(f"The segmenter at 512 x 512, {args.threads} thread(s)", COLUMNS, rows))


if __name__ == "__main__":
    main()
