"""What the 2D-S and 2D-SS command lines share: finding scenes, the results folder, the loop.

``--data`` is one scene folder (with ``transforms.json``) or a folder of scene
folders. Results go to ``--out``, by default ``<benchmark>/../results`` where
``<benchmark>`` is the folder of scene folders (for a single scene, its parent),
so ``--data /work/data/tiny`` writes to ``/work/data/results``.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path

from tqdm import tqdm

from baselines.views import PROTOCOLS
from dataset.results import MethodResult, write_result
from dataset.scene import Scene, read_scene


def scene_folders(data: Path) -> list[Path]:
    """The scene folders named by ``--data``, sorted by name.

    Raises
    ------
    ValueError
        If ``data`` is neither a scene folder nor holds any.
    """
    data = Path(data)
    if (data / "transforms.json").is_file():
        return [data]
    if not data.is_dir():
        raise ValueError(f"--data {data} does not exist")
    scenes = sorted(p for p in data.iterdir() if (p / "transforms.json").is_file())
    if not scenes:
        raise ValueError(
            f"--data {data} is neither a scene folder (with transforms.json) nor a folder of "
            "scene folders; make one with `python -m dataset.generate`"
        )
    return scenes


def default_results_folder(data: Path) -> Path:
    """``<benchmark>/../results`` (see the module docstring)."""
    data = Path(data).resolve()
    benchmark = data.parent if (data / "transforms.json").is_file() else data
    return benchmark.parent / "results"


def add_common_arguments(parser: argparse.ArgumentParser) -> None:
    """--views, --data, --out and --debug-images."""
    parser.add_argument("--views", required=True, choices=PROTOCOLS,
                        help="view protocol: 'ideal' (one perpendicular view per facade) or "
                             "'multi' (several natural views per facade)")
    parser.add_argument("--data", required=True, type=Path,
                        help="a scene folder (with transforms.json) or a folder of scene folders")
    parser.add_argument("--out", type=Path, default=None,
                        help="folder for the result JSON files (default: <benchmark>/../results, "
                             "<benchmark> being --data or, for one scene, its parent)")
    parser.add_argument("--debug-images", type=Path, default=None, metavar="DIR",
                        help="also write debug PNGs <scene>__<protocol>__f<facade>__v<k>__<kind>"
                             ".png into DIR")


def run_scenes(data: Path, out: Path | None, run_one: Callable[[Scene], MethodResult]) -> int:
    """Run one method on every scene of ``data``; write and print result files; exit code.

    Warnings and per-scene failures go to stderr; a scene that fails does not
    stop the others.

    Raises
    ------
    ValueError
        If ``data`` holds no scene or no scene could be measured.
    """
    folders = scene_folders(data)
    out = default_results_folder(data) if out is None else Path(out)
    written, failures = 0, []
    for folder in tqdm(folders, desc="scenes", unit="scene", disable=len(folders) < 2):
        try:
            result = run_one(read_scene(folder))
        except ValueError as exc:
            failures.append(str(exc))
            print(f"error: {exc}", file=sys.stderr)
            continue
        for w in result.warnings:
            print(f"warning: {w}", file=sys.stderr)
        print(write_result(out, result))
        written += 1
    if written == 0:
        raise ValueError(f"nothing was measured in {data} ({len(failures)} scene(s) failed)")
    return 0


def main_guarded(prog: str, body: Callable[[], int]) -> int:
    """Run a CLI body; a ValueError (a user's mistake) becomes one line on stderr and exit 2."""
    try:
        return body()
    except ValueError as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return 2
