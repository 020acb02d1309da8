"""Generate benchmark scene folders: ``python -m dataset.generate --preset tiny --out data/tiny``.

The scenes come from one source of :data:`dataset.sources.SOURCES` (a preset, a labelled
mesh, an IFC model, an official BuildNet3D layout; :mod:`dataset.importers.source`). One
scene folder per entry, named by the entry: a building is rendered by
:func:`dataset.scenes.scene_writer.generate_scene` (optionally in several processes, one
building each, or on a Ray cluster), a scene the source has already rendered is written as
it is; both atomically (a folder with the final name is always finished). A rerun skips
finished buildings whose provenance record (config, seed, inputs, code) matches, so an
interrupted run resumes where it stopped, and a scene made by older code is re-rendered with
the reason logged. This module is also the CLI.
"""

from __future__ import annotations

import argparse
import shutil
import signal
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, get_args

import numpy as np
from tqdm import tqdm

from dataset.importers.source import BuildingEntry, Entry, NoOptions, SceneEntry, write_scenes
from dataset.rendering.shading import LookName, RgbConfig
from dataset.rendering.street_views import STREET_FRAMES_PER_BUILDING, StreetConfig
from dataset.scenes.scene_writer import (
    GenerateConfig,
    PlannedView,
    depth_unit_for,
    generate_scene,
    only_code_changed,
    plan_views,
    scene_changes,
    scene_is_finished,
)
from dataset.source_args import (
    add_import_arguments,
    add_source_arguments,
    chosen_source,
    source_options,
)
from dataset.sources import PRESET_SOURCE, SOURCES
from envelope.cli_errors import add_debug_flag, check_output_folder, exit_cli, run_cli
from envelope.executors.ray_tasks import RayConfig, add_executor_arguments
from envelope.executors.worker_pool import worker_pool
from envelope.resources import FACADE_VIEWS_PER_BUILDING, check_generate_resources

__all__ = [
    "GenerateConfig",
    "PlannedView",
    "depth_unit_for",
    "generate_entries",
    "generate_preset",
    "generate_scene",
    "main",
    "plan_views",
    "scene_is_finished",
    "scene_seed",
]


def scene_seed(base_seed: int, recipe_seed: int) -> int:
    """Seed of one preset scene: mixes the run's seed with the recipe's."""
    return int(np.random.SeedSequence([int(base_seed), int(recipe_seed)]).generate_state(1)[0])


def generate_preset(
    name: str, out_root: str | Path, config: GenerateConfig, *, workers: int = 1, seed: int = 0,
    overwrite: bool = False, progress: bool = True, ray: RayConfig | None = None,
    log: Callable[[str], None] = tqdm.write, buildings: Sequence[str] | None = None,
) -> list[Path]:
    """Generate every building of preset ``name`` (or only those named in ``buildings``, each
    with the seed and cameras it has in the whole preset) into ``out_root``; return the scene
    folders (:func:`generate_entries` of :data:`dataset.sources.PRESET_SOURCE`'s entries).

    Raises
    ------
    ValueError
        Unknown preset or building, and as :func:`generate_entries`.
    """
    entries = PRESET_SOURCE.read(name, NoOptions())
    if buildings is not None:
        unknown = sorted(set(buildings) - {e.name for e in entries})
        if unknown:
            raise ValueError(f"preset {name} has no building {', '.join(unknown)} (it has "
                             f"{', '.join(e.name for e in entries)})")
        entries = tuple(e for e in entries if e.name in buildings)
    return generate_entries(entries, out_root, config,
                            workers=workers, seed=seed, overwrite=overwrite, progress=progress,
                            ray=ray, log=log, desc=f"preset {name}")


def generate_entries(
    entries: Sequence[Entry], out_root: str | Path, config: GenerateConfig, *, workers: int = 1,
    seed: int = 0, overwrite: bool = False, progress: bool = True, ray: RayConfig | None = None,
    log: Callable[[str], None] = tqdm.write, desc: str = "buildings",
) -> list[Path]:
    """Make a scene folder ``out_root / entry.name`` of every entry of a source; return them.

    A :class:`~dataset.importers.source.SceneEntry` is written as its source rendered it
    (kept if there, unless ``overwrite``). A building is rendered resumably: scenes whose
    provenance record matches what this code would write (config, seed, the entry's
    inputs, dataset code, libraries) are skipped; a scene that differs only by the code
    that made it is re-rendered, with the reason logged. A building's seed is ``seed`` mixed
    with the entry's own (:func:`scene_seed`), or ``seed`` itself. ``workers`` processes each
    build and render one building at a time (a single building left to do has its frames
    split over them instead). With ``ray`` each building is a task on that Ray cluster
    instead (:mod:`dataset.ray_generate`).

    Raises
    ------
    ValueError
        ``workers < 1``, unwritable ``out_root``, a scene folder made with another config,
        seed or inputs, or by code too old to say (pass ``overwrite=True`` to replace it),
        or a building that cannot be built or framed.
    """
    if workers < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    out_root = Path(out_root)
    check_writable(out_root)
    write_scenes([e for e in entries if isinstance(e, SceneEntry)], out_root,
                 overwrite=overwrite, progress=progress)
    buildings = [e for e in entries if isinstance(e, BuildingEntry)]
    todo = []
    for entry in buildings:
        s = seed if entry.seed is None else scene_seed(seed, entry.seed)
        _remove_stale_partials(out_root, entry.name)
        inputs = dict(entry.inputs)
        changes = scene_changes(out_root / entry.name, config, s, inputs)
        if not changes:
            continue
        _check_replaceable(out_root / entry.name, changes, overwrite, log)
        todo.append((entry, out_root, config, s, inputs))
    bar = tqdm(total=len(buildings), initial=len(buildings) - len(todo), desc=desc,
               unit="building", disable=not progress or not buildings)
    with bar:
        if ray is not None:
            from dataset.ray_generate import generate_on_ray

            for _ in generate_on_ray([j[0] for j in todo], out_root, config,
                                     [j[3] for j in todo], [j[4] for j in todo], ray):
                bar.update()
        elif workers == 1 or len(todo) <= 1:
            for job in todo:
                # A lone building still uses the workers: its frames are split over them.
                _generate_building(job, progress=progress, workers=workers)
                bar.update()
        else:
            _run_pool(todo, workers, bar)
    return [out_root / e.name for e in entries]


def check_writable(folder: Path) -> None:
    """Create ``folder`` if needed and make sure files can be written there (ValueError if not)."""
    check_output_folder(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ValueError(
            f"cannot write to output folder {folder}: {exc.strerror or exc}; choose another --out"
        ) from exc


def _generate_building(job: tuple, progress: bool = False, workers: int = 1) -> Path:
    entry, out_root, config, s, inputs = job
    return generate_scene(entry.build(), out_root, config, seed=s, name=entry.name,
                          progress=progress, workers=workers, inputs=inputs)


def _check_replaceable(
    scene_dir: Path, changes: list, overwrite: bool, log: Callable[[str], None]
) -> None:
    """Allow re-rendering ``scene_dir`` when it is absent, differs only by the code that made
    it (logged), or ``overwrite`` is set; otherwise raise ``ValueError`` saying why."""
    if not scene_dir.exists():
        return
    why = "; ".join(str(c) for c in changes)
    if overwrite or only_code_changed(changes):
        log(f"{scene_dir.name}: {why}; re-rendering")
        return
    raise ValueError(f"{scene_dir} holds another scene ({why}); use a new --out or "
                     "--overwrite to replace it")


def _run_pool(todo: list[tuple], workers: int, bar: tqdm) -> None:
    # Each worker deletes its unfinished scene folder when the pool is terminated.
    with worker_pool(min(workers, len(todo))) as pool:
        for _ in pool.imap_unordered(_generate_building, todo):
            bar.update()


def _interrupt_on_sigterm(signum: int, frame: Any) -> None:
    raise KeyboardInterrupt


def _remove_stale_partials(out_root: Path, name: str) -> None:
    """Remove temporary folders a killed run (SIGKILL, power loss) left for scene ``name``."""
    for stale in out_root.glob(f".{name}.*.partial"):
        shutil.rmtree(stale, ignore_errors=True)


def _parse_args(argv: list[str] | None) -> argparse.Namespace:
    d = GenerateConfig()
    p = argparse.ArgumentParser(
        prog="python -m dataset.generate",
        description=(
            "Render benchmark scene folders (RGB, z-depth, semantics, normals, facade ids, "
            "transforms.json, building.json, mesh.ply) for a built-in preset or for your own "
            "building, or import scenes an official BuildNet3D generator rendered. Finished "
            "scenes are skipped on a rerun, so an interrupted run resumes where it stopped."
        ),
        epilog=(
            "examples: python -m dataset.generate --preset tiny --out data/tiny | "
            "python -m dataset.generate --preset paper --out data/paper --workers 2 | "
            "python -m dataset.generate --mesh house.ply --out data/mine | "
            "python -m dataset.generate --ifc house.ifc --out data/mine | "
            "python -m dataset.generate --input house.ifc --out data/mine. "
            "Layout and options: docs/rendering.md; sources: docs/importing.md."
        ),
    )
    add_source_arguments(p.add_mutually_exclusive_group(required=True), SOURCES)
    p.add_argument("--out", type=Path, required=True, metavar="DIR",
                   help="folder that receives one scene folder per building")
    render = p.add_argument_group("render options (an official layout's scenes are imported "
                                  "as rendered: these are ignored)")
    render.add_argument("--resolution", type=int, default=d.resolution,
                        help=f"square image size in pixels (default {d.resolution})")
    render.add_argument("--views", type=int, default=d.views,
                        help=f"orbit views per building, split train/eval (default {d.views})")
    render.add_argument("--train-fraction", type=float, default=d.train_fraction,
                        help="share of orbit views used for training "
                             f"(default {d.train_fraction})")
    render.add_argument("--fov", type=float, default=d.fov_deg,
                        help=f"field of view in degrees (default {d.fov_deg})")
    render.add_argument("--supersampling", type=int, default=d.supersampling,
                        help="RGB anti-aliasing: rays per pixel along each axis (default 1)")
    render.add_argument("--context", action="store_true",
                        help="render the buildings around each building as occluders in every "
                             "view (sources that know them: CityGML, the lod3 preset); they are "
                             "background in the labels and the truth is unchanged "
                             "(docs/importing.md section 8)")
    render.add_argument("--street", action="store_true",
                        help="add the street frames a mobile-mapping car takes from the road "
                             "network (the lod3 preset's OpenDRIVE lanes; elsewhere a path "
                             "round the block), split 'street', placed without the truth "
                             "(docs/rendering.md, 'Street views')")
    render.add_argument("--look", choices=get_args(LookName), default=RgbConfig().look,
                        help="RGB look: 'plain' (the default, the benchmark's tables) or "
                             "'photo', the texture photographs have (brick, render, stone, "
                             "weathering, tiles, blinds behind glass, paving and road markings "
                             "on the ground) for structure from motion on the images alone; "
                             "labels and depth are the same with either (docs/rendering.md, "
                             "'Photo look')")
    render.add_argument("--seed", type=int, default=0,
                        help="seed for cameras and looks (default 0)")
    p.add_argument("--workers", type=int, default=1,
                   help="processes: with several buildings each renders one building at a "
                        "time; with one they share its frames (default 1)")
    add_executor_arguments(p, "--workers processes here", "building, with --preset")
    p.add_argument("--overwrite", action="store_true",
                   help="replace scenes that were made with another config or seed")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    add_import_arguments(p)
    add_debug_flag(p)
    return p.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    """CLI entry point; returns the exit code (0 ok, 2 bad input, 130 interrupted)."""
    args = _parse_args(argv)

    def body() -> int:
        config = GenerateConfig(
            resolution=args.resolution, views=args.views, train_fraction=args.train_fraction,
            fov_deg=args.fov, supersampling=args.supersampling, context=args.context,
            street=StreetConfig() if args.street else None, rgb=RgbConfig(look=args.look),
        )
        source, path = chosen_source(args, SOURCES)
        if args.executor == "ray" and source is not PRESET_SOURCE:
            raise ValueError("--executor ray renders a preset's buildings as tasks (each node "
                             "builds its own); with another source use --workers")
        check_output_folder(args.out)
        entries = source.read(path, source_options(source, args, progress=not args.quiet))
        _check_resources(args, config, sum(isinstance(e, BuildingEntry) for e in entries))
        ray = RayConfig(address=args.ray_address) if args.executor == "ray" else None
        scenes = generate_entries(entries, args.out, config, workers=args.workers,
                                  seed=args.seed, overwrite=args.overwrite,
                                  progress=not args.quiet, ray=ray,
                                  desc=f"{source.name} {Path(path).name}")
        for scene in scenes:
            print(scene)
        return 0

    # `kill` (SIGTERM) stops the run as cleanly as Ctrl-C does.
    previous = signal.signal(signal.SIGTERM, _interrupt_on_sigterm)
    try:
        return run_cli("dataset.generate", body, debug=args.debug, interrupted=(
            "interrupted: finished scenes are kept, unfinished ones were removed; run the same "
            "command again to resume"))
    finally:
        signal.signal(signal.SIGTERM, previous)


def _check_resources(args: argparse.Namespace, config: GenerateConfig, buildings: int) -> None:
    """Refuse ``--workers`` below 1, and a render of ``buildings`` that would not fit."""
    if args.workers < 1:
        raise ValueError(f"--workers must be >= 1, got {args.workers}")
    if buildings:
        check_generate_resources(
            config.resolution, config.supersampling, config.views + FACADE_VIEWS_PER_BUILDING
            + (STREET_FRAMES_PER_BUILDING if config.street is not None else 0),
            buildings, min(args.workers, buildings) if buildings > 1 else args.workers,
            args.out)


if __name__ == "__main__":
    exit_cli(main())
