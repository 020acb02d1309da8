"""``python -m segment.predict``: give scenes a segmenter's masks (e.g. your photos' scenes),
or segment a folder of photos.

``--data``: writes, for every scene, a copy into ``--out`` whose semantic images are the
segmenter's predictions from the RGB (:func:`segment.scene_masks.predicted_scene`): a
frame without a mask gets one, everything else is a hard link to the original. A rerun
reuses copies made by the same segmenter from the same scenes.

``--photos``: writes ``<out>/<stem>.png`` (class ids, one byte per pixel, of the upright
photo) for every image file given or in the folder given. Each photo is read by
:func:`envelope.photo_io.read_photo_rgb` (EXIF orientation applied; grey, 16-bit, CMYK,
palette and alpha images converted); one that cannot be read (truncated, corrupt) is
named with the reason on stderr and skipped, the others are segmented, and the exit
status is 1.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

from tqdm import tqdm

from envelope.cli_errors import add_debug_flag, check_output_folder, exit_cli, run_cli
from envelope.scenes.images import write_labels
from envelope.scenes.scene import find_scene_folders
from segment.scene_masks import predicted_scene
from segment.segmenter import Segmenter, resolve_segmenter, segment_photo

PHOTO_SUFFIXES = (".jpg", ".jpeg", ".png", ".tif", ".tiff", ".bmp", ".webp")
"""File endings ``--photos`` takes from a folder (any case)."""


def photo_files(photos: Path) -> list[Path]:
    """``photos`` itself if it is a file, else the image files (:data:`PHOTO_SUFFIXES`)
    directly in the folder, sorted by name."""
    if photos.is_file():
        return [photos]
    if not photos.is_dir():
        raise ValueError(f"--photos {photos}: no such file or folder")
    return sorted(p for p in photos.iterdir()
                  if p.is_file() and p.suffix.lower() in PHOTO_SUFFIXES)


def segment_photos(files: Sequence[Path], out: Path, segmenter: Segmenter) -> list[str]:
    """Write ``out/<stem>.png`` class ids for each photo; returns one line per photo that
    could not be read (its path and the reason), in order."""
    failed = []
    for path in tqdm(files, desc=f"photos by {segmenter.name}", unit="photo"):
        try:
            labels = segment_photo(segmenter, path)
        except ValueError as exc:
            failed.append(str(exc))
            continue
        write_labels(out / f"{path.stem}.png", labels)
        print(out / f"{path.stem}.png")
    return failed


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m segment.predict",
        description="Copy scenes with each view's semantic mask replaced by a segmenter's "
        "prediction from its RGB image (the truth and all other files are linked, not "
        "changed). Methods then run on the copies as on any scene.",
        epilog="examples: python -m segment.predict --data data/mine --out data/mine-masks; "
        "python -m segment.predict --photos my_photos --out my_photos-masks",
    )
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("--data", type=Path,
                        help="a scene folder or a folder of scene folders")
    source.add_argument("--photos", type=Path,
                        help="a photo or a folder of photos (jpg, png, tif, bmp, webp): "
                        "writes OUT/<stem>.png class ids per photo")
    parser.add_argument("--out", type=Path, required=True,
                        help="folder that receives one scene folder per scene (--data) or "
                        "one label image per photo (--photos)")
    parser.add_argument("--model", default=None,
                        help="'default' (the committed weights), a weights file (*.pt) or an "
                        "installed segmenter plugin's name (default: default)")
    parser.add_argument("--threads", type=int, default=2, help="torch threads (default: 2)")
    add_debug_flag(parser)
    args = parser.parse_args(argv)

    def photos_body() -> int:
        files = photo_files(args.photos)
        if not files:
            raise ValueError(f"--photos {args.photos} holds no image file "
                             f"({', '.join(PHOTO_SUFFIXES)})")
        if args.out.resolve() in {f.resolve().parent for f in files}:
            raise ValueError(f"--out {args.out} holds the photos themselves; choose another "
                             f"folder")
        check_output_folder(args.out)
        failed = segment_photos(files, args.out, resolve_segmenter(args.model,
                                                                   threads=args.threads))
        for line in failed:
            print(f"skipped {line}", file=sys.stderr)
        return 1 if failed else 0

    def body() -> int:
        if args.photos is not None:
            return photos_body()
        dirs = find_scene_folders(args.data, with_images=True)
        check_output_folder(args.out)
        if args.out.resolve() in {d.resolve().parent for d in dirs}:
            raise ValueError(f"--out {args.out} holds the scenes themselves; choose another "
                             f"folder")
        segmenter = resolve_segmenter(args.model, threads=args.threads)
        for scene_dir in tqdm(dirs, desc=f"masks by {segmenter.name}", unit="scene"):
            print(predicted_scene(scene_dir, args.out, segmenter))
        return 0

    return run_cli("segment.predict", body, debug=args.debug,
                   interrupted="interrupted: finished copies are kept, run again to resume")


if __name__ == "__main__":
    exit_cli(main())
