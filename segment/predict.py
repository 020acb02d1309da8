"""``python -m segment.predict``: give scenes a segmenter's masks (e.g. your photos' scenes).

Writes, for every scene of ``--data``, a copy into ``--out`` whose semantic images are the
segmenter's predictions from the RGB (:func:`segment.scene_masks.predicted_scene`): a
frame without a mask gets one, everything else is a hard link to the original. A rerun
reuses copies made by the same segmenter from the same scenes.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path

from tqdm import tqdm

from dataset.core.cli_errors import add_debug_flag, check_output_folder, exit_cli, run_cli
from segment.scene_masks import predicted_scene, scene_folders
from segment.segmenter import resolve_segmenter


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m segment.predict",
        description="Copy scenes with each view's semantic mask replaced by a segmenter's "
        "prediction from its RGB image (the truth and all other files are linked, not "
        "changed). Methods then run on the copies as on any scene.",
        epilog="example: python -m segment.predict --data data/mine --out data/mine-masks",
    )
    parser.add_argument("--data", type=Path, required=True,
                        help="a scene folder or a folder of scene folders")
    parser.add_argument("--out", type=Path, required=True,
                        help="folder that receives one scene folder per scene")
    parser.add_argument("--model", default=None,
                        help="'default' (the committed weights), a weights file (*.pt) or an "
                        "installed segmenter plugin's name (default: default)")
    parser.add_argument("--threads", type=int, default=2, help="torch threads (default: 2)")
    add_debug_flag(parser)
    args = parser.parse_args(argv)

    def body() -> int:
        dirs = scene_folders(args.data)
        if not dirs:
            raise ValueError(f"--data {args.data} holds no scene folder (one with "
                             f"transforms.json)")
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
