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

from dataset.core.cli_errors import add_debug_flag, check_output_folder, one_line, run_cli
from dataset.core.method_input import MethodInput
from dataset.core.protocols import VIEW_PROTOCOLS
from dataset.core.results import MethodResult, write_result
from dataset.core.warnings_summary import summarise_warnings
from dataset.scenes.scene import read_method_input


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
    """--views, --data, --out, --debug-images and --debug."""
    parser.add_argument("--views", required=True, choices=VIEW_PROTOCOLS,
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
    add_debug_flag(parser)


def run_scenes(data: Path, out: Path | None, run_one: Callable[[MethodInput], MethodResult]) -> int:
    """Run one method on every scene of ``data``; write and print result files; exit code.

    Warnings and per-scene failures go to stderr; a scene that fails does not
    stop the others.

    Raises
    ------
    ValueError
        If ``data`` holds no scene or no scene could be measured.
    """
    folders = scene_folders(data)
    out = check_output_folder(default_results_folder(data) if out is None else Path(out))
    written, failures = 0, []
    for folder in tqdm(folders, desc="scenes", unit="scene", disable=len(folders) < 2):
        try:
            result = run_one(read_method_input(folder))
        except ValueError as exc:
            failures.append(one_line(exc))
            if len(folders) > 1:
                print(f"error: {failures[-1]}", file=sys.stderr)
            continue
        for w in summarise_warnings(result.warnings):
            print(f"warning: {w}", file=sys.stderr)
        print(write_result(out, result))
        written += 1
    if written == 0:
        if len(folders) == 1:
            raise ValueError(failures[0])
        raise ValueError(f"nothing was measured in {data} ({len(failures)} scene(s) failed)")
    return 0


def main_guarded(prog: str, body: Callable[[], int], debug: bool = False) -> int:
    """Run a CLI body: a user's mistake becomes one line on stderr and exit 2
    (:func:`dataset.core.cli_errors.run_cli`)."""
    return run_cli(prog, body, debug=debug)
