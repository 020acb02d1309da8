"""The segmenter on real labelled street photos: its window IoU as a domain-gap figure.

    git clone https://github.com/cvjena/labelmefacade /tmp/labelmefacade
    python bench/segment_photos.py --labelmefacade /tmp/labelmefacade --threads 1

LabelMeFacade (Fröhlich, Rodner and Denzler, ICPR 2010): 945 street photos taken from
LabelMe, labelled per pixel (various, building, car, door, pavement, road, sky,
vegetation, window), with a list of 845 test images (``test.txt``, 844 lines). The images may
be used "only for non-commercial and research experiments" (its README): they are read
from a clone and never copied into this repository.

Its classes are mapped to the project's: window -> window, door -> door, building ->
wall (roofs are part of it: the photos are taken from the street), sky, vegetation,
road, pavement and car -> background; ``various`` (unlabelled) pixels are not counted.
Printed (Markdown): the window IoU pooled over the images (intersection and union
summed first) and its mean over the images that have windows, the share of window
pixels found (recall) and of predicted window pixels that are windows (precision),
and the building IoU (wall, window, door and roof against building, window and door).
Nothing is tuned on these photos: the segmenter is the one the command names, run once
on every listed image at its own size.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

# Run as a script, this file's folder is sys.path[0]: put the repository root there instead.
sys.path[0] = str(Path(__file__).resolve().parent.parent)

import numpy as np  # noqa: E402
from tqdm import tqdm  # noqa: E402

from dataset.core.classes import NUM_CLASSES, SemanticClass  # noqa: E402
from dataset.scenes.images import read_rgb  # noqa: E402
from segment.evaluate import confusion_matrix, iou_per_class  # noqa: E402
from segment.segmenter import resolve_segmenter, segment_rgb  # noqa: E402

IGNORED = 255
"""Label of pixels that are not counted (LabelMeFacade's ``various``)."""
# LabelMeFacade's label colours (R, G, B), from its README, and the project class of each.
LABELMEFACADE_CLASSES: dict[tuple[int, int, int], int] = {
    (0, 0, 0): IGNORED,  # various
    (128, 0, 0): SemanticClass.WALL,  # building
    (128, 0, 128): SemanticClass.BACKGROUND,  # car
    (128, 128, 0): SemanticClass.DOOR,  # door
    (128, 128, 128): SemanticClass.BACKGROUND,  # pavement
    (128, 64, 0): SemanticClass.BACKGROUND,  # road
    (0, 128, 128): SemanticClass.BACKGROUND,  # sky
    (0, 128, 0): SemanticClass.BACKGROUND,  # vegetation
    (0, 0, 128): SemanticClass.WINDOW,  # window
}
BUILDING = (SemanticClass.WALL, SemanticClass.WINDOW, SemanticClass.ROOF, SemanticClass.DOOR)


def labelmefacade_labels(label_rgb: np.ndarray) -> np.ndarray:
    """(H, W, 3) uint8 LabelMeFacade label colours -> (H, W) uint8 project class ids
    (:data:`IGNORED` for ``various`` and any colour not in the list)."""
    out = np.full(label_rgb.shape[:2], IGNORED, np.uint8)
    for colour, cls in LABELMEFACADE_CLASSES.items():
        out[np.all(label_rgb == colour, axis=-1)] = cls
    return out


def building_only(labels: np.ndarray) -> np.ndarray:
    """(H, W) class ids -> 1 on the building (wall, window, roof, door), 0 elsewhere,
    :data:`IGNORED` kept."""
    out = np.isin(labels, BUILDING).astype(np.uint8)
    out[labels == IGNORED] = IGNORED
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--labelmefacade", type=Path, required=True,
                        help="a clone of github.com/cvjena/labelmefacade")
    parser.add_argument("--list", default="test.txt",
                        help="the image list inside it (default: test.txt)")
    parser.add_argument("--model", default=None,
                        help="'default', a weights file or a segmenter plugin (default: default)")
    parser.add_argument("--threads", type=int, default=2, help="torch threads (default: 2)")
    args = parser.parse_args(argv)
    listing = args.labelmefacade / args.list
    if not listing.is_file():
        parser.error(f"{listing} not found: clone github.com/cvjena/labelmefacade and give "
                     f"its folder")
    images = [line.strip() for line in listing.read_text().splitlines() if line.strip()]
    segmenter = resolve_segmenter(args.model, threads=args.threads)
    confusion = np.zeros((NUM_CLASSES, NUM_CLASSES), np.int64)
    building = np.zeros((2, 2), np.int64)
    per_image = []
    start = time.process_time()
    for name in tqdm(images, desc="photos", unit="image"):
        rgb = read_rgb(args.labelmefacade / name)
        exact = labelmefacade_labels(
            read_rgb(args.labelmefacade / "labels" / f"{Path(name).stem}.png"))
        predicted = segment_rgb(segmenter, rgb)
        c = confusion_matrix(predicted, exact)
        confusion += c
        b_pred, b_exact = building_only(predicted), building_only(exact)
        keep = b_exact != IGNORED
        building += np.bincount(b_exact[keep] * 2 + b_pred[keep], minlength=4).reshape(2, 2)
        if c[SemanticClass.WINDOW].sum() > 0:
            per_image.append(iou_per_class(c)[SemanticClass.WINDOW])
    window = SemanticClass.WINDOW
    tp = confusion[window, window]
    print(f"LabelMeFacade {args.list}: {len(images)} photos, segmenter {segmenter.name} "
          f"({time.process_time() - start:.0f} CPU s)\n")
    print("| measure | value |\n|---|---|")
    print(f"| window IoU, pooled over the photos | {iou_per_class(confusion)[window]:.3f} |")
    print(f"| window IoU, mean over the {len(per_image)} photos with windows | "
          f"{np.mean(per_image):.3f} |")
    print(f"| window recall (window pixels found) | {tp / confusion[window].sum():.3f} |")
    print(f"| window precision (predicted windows that are) | "
          f"{tp / max(confusion[:, window].sum(), 1):.3f} |")
    print(f"| building IoU (wall, window, roof, door) | "
          f"{iou_per_class(building)[1]:.3f} |")
    found = confusion[window] / confusion[window].sum()
    print("\nwindow pixels predicted as: " + ", ".join(
        f"{SemanticClass(k).name.lower()} {found[k]:.2f}" for k in range(NUM_CLASSES)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
