"""Masks the two committed segmenters make, for docs/segment.md:
``python docs/images/make_segment_examples.py [--scratch DIR]``.

Three rows, each an image and what is known of it, then each weights' masks:

- a procedural building (the ``tiny`` preset's realistic house), its orbit view with the
  most window pixels in its exact labels;
- a real building of the ``lod3`` preset (Ingolstadt 4018106) with its neighbours in place,
  the street view (``--street --context``) with the most window pixels of the building;
- a real photo (``tests/fixtures/photo_building``, MIT, unlabelled).

Columns: the image, its exact labels (a blank panel for the photo), the render weights'
masks (``renders``, the default), the photo weights' masks (``photos``). Views are chosen
by a rule on the exact labels, not by looking at the masks. The two scenes are rendered
into ``--scratch`` (kept there, so a rerun reuses them; default a temporary folder), a few
minutes on 2 cores. Writes ``docs/images/segment_examples.png`` and prints the share of
each image that each set of masks calls window.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import cv2
import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from dataset.generate import generate_preset  # noqa: E402
from dataset.rendering.street_views import StreetConfig  # noqa: E402
from dataset.scenes.scene_writer import GenerateConfig  # noqa: E402
from envelope.classes import SemanticClass  # noqa: E402
from envelope.photo_io import read_photo_rgb  # noqa: E402
from figures.style import colour_labels  # noqa: E402
from segment.segmenter import resolve_segmenter, segment_rgb  # noqa: E402

PHOTO = ROOT / "tests" / "fixtures" / "photo_building" / "palace-of-culture-400px.jpg"
OUT = Path(__file__).resolve().parent / "segment_examples.png"
PANEL_HEIGHT_PX = 256
WEIGHTS = ("renders", "photos")


def most_windows_frame(scene: Path, prefix: str) -> str:
    """The file stem of ``scene``'s ``images/<prefix>*.png`` whose exact labels have the most
    window pixels (ties: the first in name order)."""
    stems = sorted(p.stem for p in (scene / "images").glob(f"{prefix}*.png"))
    if not stems:
        raise ValueError(f"{scene} has no images named {prefix}*.png")
    counts = [int((cv2.imread(str(scene / "semantics" / f"{s}.png"),
                              cv2.IMREAD_UNCHANGED) == SemanticClass.WINDOW).sum()) for s in stems]
    return stems[int(np.argmax(counts))]


def scene_example(scene: Path, prefix: str) -> tuple[np.ndarray, np.ndarray]:
    """(rgb (H, W, 3) uint8, exact labels (H, W) uint8) of the chosen frame."""
    stem = most_windows_frame(scene, prefix)
    rgb = read_photo_rgb(scene / "images" / f"{stem}.png")
    labels = cv2.imread(str(scene / "semantics" / f"{stem}.png"), cv2.IMREAD_UNCHANGED)
    return rgb, labels


def fit_height(image: np.ndarray, height_px: int = PANEL_HEIGHT_PX) -> np.ndarray:
    """(H, W, 3) -> (height_px, W * height_px / H, 3), nearest neighbour (labels stay labels)."""
    width = max(1, round(image.shape[1] * height_px / image.shape[0]))
    return cv2.resize(image, (width, height_px), interpolation=cv2.INTER_NEAREST)


def example_row(name: str, rgb: np.ndarray, labels: np.ndarray | None,
                segmenters: list) -> np.ndarray:
    """(PANEL_HEIGHT_PX, 4 panels wide, 3) uint8: image | exact labels | each weights' masks.
    Prints the share of the image each set of masks calls window."""
    exact = colour_labels(labels) if labels is not None else np.full_like(rgb, 255)
    masks = [segment_rgb(s, rgb) for s in segmenters]
    shares = [("exact", labels)] if labels is not None else []
    shares += [(s.name, m) for s, m in zip(segmenters, masks, strict=True)]
    print(f"{name}: window share of the image " + ", ".join(
        f"{n} {(m == SemanticClass.WINDOW).mean():.3f}" for n, m in shares))
    predicted = [colour_labels(m) for m in masks]
    gap = np.full((PANEL_HEIGHT_PX, 6, 3), 255, np.uint8)
    panels = [fit_height(p) for p in (rgb, exact, *predicted)]
    return np.concatenate([x for p in panels for x in (p, gap)][:-1], axis=1)


def render_scenes(scratch: Path) -> tuple[Path, Path]:
    """The tiny realistic house (orbit) and lod3 4018106 (street, neighbours) under ``scratch``."""
    tiny = generate_preset("tiny", scratch / "tiny", GenerateConfig(views=24, ideal=False,
                           multi=False), buildings=["realistic_house"], progress=False)[0]
    lod3 = generate_preset("lod3", scratch / "lod3", GenerateConfig(
        views=2, ideal=False, multi=False, context=True, street=StreetConfig()),
        buildings=["4018106"], progress=False)[0]
    return tiny, lod3


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python docs/images/make_segment_examples.py",
                                description=__doc__.split("\n\n")[1])
    p.add_argument("--scratch", type=Path, default=None,
                   help="folder for the two rendered scenes (default: a temporary folder)")
    args = p.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        tiny, lod3 = render_scenes(args.scratch or Path(tmp))
        segmenters = [resolve_segmenter(w, threads=2) for w in WEIGHTS]
        rows = [example_row("tiny realistic house", *scene_example(tiny, "train"), segmenters),
                example_row("lod3 4018106 street", *scene_example(lod3, "street"), segmenters),
                example_row("real photo", read_photo_rgb(PHOTO), None, segmenters)]
    width = max(r.shape[1] for r in rows)
    rows = [np.pad(r, ((0, 6), (0, width - r.shape[1]), (0, 0)), constant_values=255)
            for r in rows]
    sheet = np.concatenate(rows, axis=0)[:-6]
    cv2.imwrite(str(OUT), np.ascontiguousarray(sheet[..., ::-1]), [cv2.IMWRITE_PNG_COMPRESSION, 9])
    print(OUT)
    return 0


if __name__ == "__main__":
    sys.exit(main())
