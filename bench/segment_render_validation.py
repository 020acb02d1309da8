"""Window IoU of each weights file on the render validation buildings one weights file's
record names; prints a Markdown table.

    python bench/segment_render_validation.py --data data/segtrain-512 \
        [--record segment/weights/photos.pt] [--weights photos renders] [--frames 8]

The buildings are those ``--record``'s training validated on (``validated_on``, render
scenes only, read from ``--data``); every weights file is scored as the training validates
(:func:`segment.train.validation_iou`: ``--frames`` evenly spaced frames per building, IoU pooled
per building, then the mean over buildings; the network's scores without a calibration
offset). It answers whether photo-trained weights keep the render weights' accuracy on
renders (docs/decisions.md, 2026-11-29, "A wider segmenter").
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench.tables import markdown_table  # noqa: E402
from envelope.classes import SemanticClass  # noqa: E402
from segment.calibrate import validation_scenes  # noqa: E402
from segment.train import validation_iou  # noqa: E402
from segment.weights import BUILT_IN_WEIGHTS, load_network  # noqa: E402

COLUMNS = ("weights", "validation buildings", "frames each", "window IoU", "wall IoU")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", type=Path, action="append", required=True,
                        help="a folder holding the validation buildings (repeat for several)")
    parser.add_argument("--record", default="photos",
                        help="built-in name or weights file whose validation buildings are "
                        "used (default photos)")
    parser.add_argument("--weights", nargs="+", default=sorted(BUILT_IN_WEIGHTS),
                        help="built-in names or weights files (default: every built-in)")
    parser.add_argument("--frames", type=int, default=8, help="frames per building (default 8)")
    parser.add_argument("--threads", type=int, default=2, help="torch threads (default 2)")
    args = parser.parse_args()
    _, record = load_network(BUILT_IN_WEIGHTS.get(args.record, args.record))
    renders = {**record, "validated_on": [v for v in record["validated_on"] if "set" not in v]}
    scenes = validation_scenes(renders, args.data)
    rows = []
    for name in args.weights:
        model, _ = load_network(BUILT_IN_WEIGHTS.get(name, name))
        iou = validation_iou(model, scenes, args.frames, args.threads)
        rows.append([name, len(scenes), args.frames, f"{iou[SemanticClass.WINDOW]:.3f}",
                     f"{iou[SemanticClass.WALL]:.3f}"])
    print(markdown_table(f"Render validation buildings of {args.record}", COLUMNS, rows))


if __name__ == "__main__":
    main()
