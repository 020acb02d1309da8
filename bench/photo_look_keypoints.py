"""SIFT keypoints per image in the plain and the photo look; prints a Markdown table.

    python bench/photo_look_keypoints.py [--preset P --building B ...] [--views N]
        [--resolution PX]

Renders ``--views`` orbit views of each building (``--preset``/``--building`` pairs; default
the lod3 preset's 4018106 and the tiny preset's tiny_l_shaped) in both looks
(``RgbConfig.look``, :mod:`dataset.rendering.photo_look`), same seed and cameras, and counts
the SIFT keypoints COLMAP's extractor (pycolmap, default options, CPU) finds in each RGB
image. It also compares every truth image (depth, semantics, normals, instances) of the two
renders byte for byte: the look must change the RGB alone.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from PIL import Image

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench.tables import markdown_table  # noqa: E402
from dataset.generate import generate_preset  # noqa: E402
from dataset.rendering.shading import RgbConfig  # noqa: E402
from dataset.scenes.scene_writer import GenerateConfig  # noqa: E402
from envelope.scenes.scene import read_scene  # noqa: E402

LOOKS = ("plain", "photo")
TRUTH_FOLDERS = ("depth", "semantics", "normals", "instances")
COLUMNS = ("building", "look", "views", "keypoints min", "median", "max",
           "render s / view", "truth images identical")


def keypoints_per_image(scene_dir: Path) -> list[int]:
    """SIFT keypoints COLMAP finds in each RGB image of the scene (frame order)."""
    import pycolmap

    extractor = pycolmap.FeatureExtractor.create(pycolmap.FeatureExtractionOptions(),
                                                 device=pycolmap.Device.cpu)
    scene = read_scene(scene_dir)
    counts = []
    for frame in scene.frames:
        gray = np.asarray(Image.open(scene.path(frame.file_path)).convert("L"))
        keypoints, _ = extractor.extract_from_uint8_array(gray)
        counts.append(len(keypoints))
    return counts


def truth_identical(a: Path, b: Path) -> bool:
    """Whether two scene folders hold byte-identical truth images."""
    files = [p.relative_to(a) for folder in TRUTH_FOLDERS for p in sorted((a / folder).glob("*"))]
    return bool(files) and all((a / f).read_bytes() == (b / f).read_bytes() for f in files)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--preset", action="append", help="preset of each --building")
    p.add_argument("--building", action="append", help="building of that preset")
    p.add_argument("--views", type=int, default=6, help="orbit views (default 6)")
    p.add_argument("--resolution", type=int, default=1024, help="image size (default 1024)")
    args = p.parse_args(argv)
    presets = args.preset or ["lod3", "tiny"]
    buildings = args.building or ["4018106", "tiny_l_shaped"]
    if len(presets) != len(buildings):
        p.error("give one --preset per --building")
    rows = []
    with tempfile.TemporaryDirectory(prefix="photo-look-") as tmp:
        for preset, building in zip(presets, buildings):
            scenes = {}
            for look in LOOKS:
                config = GenerateConfig(resolution=args.resolution, views=args.views,
                                        ideal=False, multi=False, rgb=RgbConfig(look=look))
                start = time.perf_counter()
                scenes[look], = generate_preset(preset, Path(tmp) / look, config,
                                                buildings=[building], progress=False)
                seconds = (time.perf_counter() - start) / args.views
                counts = keypoints_per_image(scenes[look])
                rows.append([building, look, args.views, min(counts),
                             f"{np.median(counts):.0f}", max(counts), f"{seconds:.1f}", ""])
            rows[-1][-1] = "yes" if truth_identical(scenes["plain"], scenes["photo"]) else "NO"
    print(markdown_table(f"SIFT keypoints per image ({args.resolution} px)", COLUMNS, rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
