"""Generate benchmark scene folders: ``python -m dataset.generate --preset tiny --out data/tiny``.

One scene folder per building, named by the building id, written by
:func:`dataset.scenes.scene_writer.generate_scene` (atomically: a folder with the
final name is always finished). This module runs a whole preset (optionally
in several processes, one building each) or a user's mesh, and is the CLI.
A rerun skips finished scenes whose provenance record (config, seed, inputs,
code) matches, so an interrupted run resumes where it stopped, and a scene made
by older code is re-rendered with the reason logged.
"""

from __future__ import annotations

import argparse
import shutil
import signal
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

from dataset.core.cli_errors import add_debug_flag, check_output_folder, run_cli
from dataset.core.resources import FACADE_VIEWS_PER_BUILDING, check_generate_resources
from dataset.executors.ray_tasks import RayConfig, add_executor_arguments
from dataset.executors.worker_pool import worker_pool
from dataset.importers.import_config import add_import_arguments
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

__all__ = [
    "GenerateConfig",
    "PlannedView",
    "depth_unit_for",
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
    log: Callable[[str], None] = tqdm.write,
) -> list[Path]:
    """Generate every building of preset ``name`` into ``out_root``; return the scene folders.

    Resumable: scenes whose provenance record matches what this code would write
    (config, seed, recipe, dataset code, libraries) are skipped; a scene that
    differs only by the code that made it is re-rendered, with the reason logged.
    ``workers`` processes each build and render one building at a time (a single
    building left to do has its frames split over them instead). With ``ray``
    each building is a task on that Ray cluster instead (:mod:`dataset.ray_generate`).

    Raises
    ------
    ValueError
        Unknown preset, ``workers < 1``, unwritable ``out_root``, a scene folder
        made with another config, seed or recipe, or by code too old to say
        (pass ``overwrite=True`` to replace it),
        or a building that cannot be framed.
    """
    from dataset.presets import preset_recipes

    if workers < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    recipes = preset_recipes(name)
    out_root = Path(out_root)
    check_writable(out_root)
    todo = []
    for recipe in recipes:
        s = scene_seed(seed, recipe.seed)
        scene_dir = out_root / recipe.id
        _remove_stale_partials(out_root, recipe.id)
        inputs = {"preset": name, "recipe": recipe.id}
        changes = scene_changes(scene_dir, config, s, inputs)
        if not changes:
            continue
        _check_replaceable(scene_dir, changes, overwrite, log)
        todo.append((recipe, out_root, config, s, inputs))
    bar = tqdm(total=len(recipes), initial=len(recipes) - len(todo), desc=f"preset {name}",
               unit="building", disable=not progress)
    with bar:
        if ray is not None:
            from dataset.ray_generate import generate_on_ray

            for _ in generate_on_ray([j[0] for j in todo], out_root, config,
                                     [j[3] for j in todo], [j[4] for j in todo], ray):
                bar.update()
        elif workers == 1 or len(todo) <= 1:
            for job in todo:
                # A lone building still uses the workers: its frames are split over them.
                _generate_recipe(job, progress=progress, workers=workers)
                bar.update()
        else:
            _run_pool(todo, workers, bar)
    return [out_root / r.id for r in recipes]


def check_writable(folder: Path) -> None:
    """Create ``folder`` if needed and make sure files can be written there (ValueError if not)."""
    check_output_folder(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ValueError(
            f"cannot write to output folder {folder}: {exc.strerror or exc}; choose another --out"
        ) from exc


def _generate_recipe(job: tuple, progress: bool = False, workers: int = 1) -> Path:
    from dataset.presets import build_building

    recipe, out_root, config, s, inputs = job
    building = build_building(recipe)
    return generate_scene(building, out_root, config, seed=s, name=recipe.id, progress=progress,
                          workers=workers, inputs=inputs)


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
        for _ in pool.imap_unordered(_generate_recipe, todo):
            bar.update()


def _interrupt_on_sigterm(signum: int, frame: Any) -> None:
    raise KeyboardInterrupt


def _remove_stale_partials(out_root: Path, name: str) -> None:
    """Remove temporary folders a killed run (SIGKILL, power loss) left for scene ``name``."""
    for stale in out_root.glob(f".{name}.*.partial"):
        shutil.rmtree(stale, ignore_errors=True)


def _parse_args(argv: list[str] | None) -> argparse.Namespace:
    try:
        from dataset.presets import PRESETS
    except ImportError:
        PRESETS = ("paper", "tiny")
    d = GenerateConfig()
    p = argparse.ArgumentParser(
        prog="python -m dataset.generate",
        description=(
            "Render benchmark scene folders (RGB, z-depth, semantics, normals, facade ids, "
            "transforms.json, building.json, mesh.ply) for a built-in preset or for your own "
            "labelled mesh. Finished scenes are skipped on a rerun, so an interrupted run "
            "resumes where it stopped."
        ),
        epilog=(
            "examples: python -m dataset.generate --preset tiny --out data/tiny | "
            "python -m dataset.generate --preset paper --out data/paper --workers 2 | "
            "python -m dataset.generate --mesh house.ply --out data/mine | "
            "python -m dataset.generate --ifc house.ifc --out data/mine | "
            "python -m dataset.generate --citygml city.gml --out data/city | "
            "python -m dataset.generate --preset lod3 --out data/lod3. "
            "Layout and options: docs/rendering.md."
        ),
    )
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--preset", choices=PRESETS, help="built-in set of procedural buildings")
    src.add_argument("--mesh", type=Path, metavar="FILE",
                     help="your labelled mesh (.ply with per-face label, or .obj/.glb with "
                          "class-named parts), metres, z up; see docs/importing.md")
    src.add_argument("--ifc", type=Path, metavar="FILE",
                     help="an IFC model (ArchiCAD, Revit, ... export); see docs/importing.md")
    src.add_argument("--citygml", type=Path, metavar="FILE_OR_DIR",
                     help="CityGML 2.0/3.0 LoD3 buildings: a .gml/.xml file (also .gz/.xz) or "
                          "a folder of them; one scene per Building/BuildingPart with a "
                          "window or door; see docs/importing.md (CityGML)")
    p.add_argument("--ifc-classes", type=Path, metavar="JSON",
                   help="with --ifc: your entity/GlobalId -> class mapping, e.g. "
                        '{"IfcCovering": "wall", "IfcRailing": "skip"}')
    src.add_argument("--buildnet3d", type=Path, metavar="PATH",
                     help="output of an official BuildNet3D generator: the Blender "
                          "generator's root or one images/building<i> folder, or a BlenderProc "
                          "generator/dataparser folder (meta_data.json, images/, semantic(s)/) "
                          "or a folder of them; one scene per building, as rendered (render "
                          "options are ignored); see docs/importing.md")
    p.add_argument("--out", type=Path, required=True, metavar="DIR",
                   help="folder that receives one scene folder per building")
    p.add_argument("--resolution", type=int, default=d.resolution,
                   help=f"square image size in pixels (default {d.resolution})")
    p.add_argument("--views", type=int, default=d.views,
                   help=f"orbit views per building, split train/eval (default {d.views})")
    p.add_argument("--train-fraction", type=float, default=d.train_fraction,
                   help=f"share of orbit views used for training (default {d.train_fraction})")
    p.add_argument("--fov", type=float, default=d.fov_deg,
                   help=f"field of view in degrees (default {d.fov_deg})")
    p.add_argument("--supersampling", type=int, default=d.supersampling,
                   help="RGB anti-aliasing: rays per pixel along each axis (default 1)")
    p.add_argument("--workers", type=int, default=1,
                   help="processes: with --preset each renders one building at a time; with "
                        "--mesh they share the building's frames (default 1)")
    add_executor_arguments(p, "--workers processes here", "building, with --preset")
    p.add_argument("--seed", type=int, default=0, help="seed for cameras and looks (default 0)")
    p.add_argument("--overwrite", action="store_true",
                   help="replace scenes that were made with another config or seed")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    add_import_arguments(p)  # with --mesh or --ifc
    add_debug_flag(p)
    return p.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    """CLI entry point; returns the exit code (0 ok, 2 bad input, 130 interrupted)."""
    args = _parse_args(argv)

    def body() -> int:
        config = GenerateConfig(
            resolution=args.resolution, views=args.views, train_fraction=args.train_fraction,
            fov_deg=args.fov, supersampling=args.supersampling,
        )
        if args.executor == "ray" and args.preset is None:
            raise ValueError("--executor ray renders a preset's buildings as tasks; with --mesh "
                             "use --workers to split one building's frames over processes")
        check_output_folder(args.out)
        if args.buildnet3d is not None:
            from dataset.importers.official import import_official

            scenes = import_official(args.buildnet3d, args.out, overwrite=args.overwrite)
        elif args.preset is not None:
            _check_resources(args, config)
            ray = RayConfig(address=args.ray_address) if args.executor == "ray" else None
            scenes = generate_preset(args.preset, args.out, config, workers=args.workers,
                                     seed=args.seed, overwrite=args.overwrite,
                                     progress=not args.quiet, ray=ray)
        elif args.citygml is not None:
            scenes = _generate_citygml(args, config)
        else:
            scenes = [_generate_mesh(args, config)]
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


def _check_resources(args: argparse.Namespace, config: GenerateConfig) -> None:
    from dataset.presets import preset_recipes

    if args.workers < 1:
        raise ValueError(f"--workers must be >= 1, got {args.workers}")
    scenes = len(preset_recipes(args.preset)) if args.preset is not None else 1
    check_generate_resources(config.resolution, config.supersampling,
                             config.views + FACADE_VIEWS_PER_BUILDING, scenes,
                             min(args.workers, scenes) if scenes > 1 else args.workers, args.out)


def _generate_citygml(args: argparse.Namespace, config: GenerateConfig) -> list[Path]:
    """Every building of ``--citygml`` that has a covered facade, one scene each. All files
    are read before anything is written, so bad input leaves ``--out`` as it was."""
    from dataset.core.provenance import file_fingerprint
    from dataset.importers.citygml_import import import_citygml
    from dataset.importers.citygml_read import citygml_files

    files = citygml_files(args.citygml)
    jobs = []
    for path in tqdm(files, desc="CityGML", unit="file", disable=args.quiet or len(files) < 2):
        for building in import_citygml(path):
            if building.truth.facades:
                jobs.append((building, {"citygml": file_fingerprint(path),
                                        "building": building.truth.id}))
            else:
                tqdm.write(f"{path}: building {building.truth.id} has no window or door "
                           "modelled (no covered facade): skipped")
    if not jobs:
        raise ValueError(f"{args.citygml}: no building with a window or door modelled; the "
                         "benchmark needs LoD3 openings (WallSurface with Window/Door)")
    check_writable(args.out)
    scenes = []
    for building, inputs in tqdm(jobs, desc="scenes", unit="building",
                                 disable=args.quiet or len(jobs) < 2):
        name = building.truth.id
        _remove_stale_partials(args.out, name)
        changes = scene_changes(args.out / name, config, args.seed, inputs)
        if changes:
            _check_replaceable(args.out / name, changes, args.overwrite, tqdm.write)
            generate_scene(building, args.out, config, seed=args.seed,
                           progress=not args.quiet, workers=args.workers, inputs=inputs)
        scenes.append(args.out / name)
    return scenes


def _generate_mesh(args: argparse.Namespace, config: GenerateConfig) -> Path:
    from dataset.importers.import_source import import_from_args, import_inputs

    building = import_from_args(args)
    check_writable(args.out)
    name = building.truth.id
    _remove_stale_partials(args.out, name)
    scene_dir = args.out / name
    inputs = import_inputs(args)
    changes = scene_changes(scene_dir, config, args.seed, inputs)
    if not changes:
        return scene_dir
    _check_replaceable(scene_dir, changes, args.overwrite, tqdm.write)
    return generate_scene(building, args.out, config, seed=args.seed, progress=not args.quiet,
                          workers=args.workers, inputs=inputs)


if __name__ == "__main__":
    sys.exit(main())
