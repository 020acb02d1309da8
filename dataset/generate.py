"""Generate benchmark scene folders: ``python -m dataset.generate --preset tiny --out data/tiny``.

One scene folder per building (DESIGN.md layout), named by the building id:
orbit views (Algorithm 1) split into train/eval, one ideal view per facade and
five multi views per facade, each with RGB, z-depth, semantics, normals and
facade ids (``instances/``: ground truth for tests and evaluation only).

Each scene is written into a hidden temporary folder and renamed into place
when complete (:func:`dataset.atomic.atomic_directory`), so a folder with the
final name is always finished. A rerun skips finished scenes made with the same
config and seed, which makes interrupted runs resumable.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import shutil
import signal
import sys
import tempfile
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

from dataset.atomic import atomic_directory
from dataset.camera import Intrinsics
from dataset.cameras import (
    FacadeViewConfig,
    OrbitConfig,
    ideal_views,
    multi_views,
    sample_orbit_views,
)
from dataset.images import (
    DEPTH_MAX_UNITS,
    write_depth_m,
    write_facade_ids,
    write_labels,
    write_normals,
    write_rgb,
)
from dataset.mesh import write_labelled_ply
from dataset.render import Raycaster, render_view
from dataset.results import code_version
from dataset.scene import Frame, Scene, Split, write_transforms
from dataset.shading import RgbConfig
from dataset.truth import Building, write_building


@dataclass(frozen=True)
class GenerateConfig:
    """What a scene holds and how it is rendered.

    ``resolution``: square image size in pixels. ``views``: orbit views, split
    ``train_fraction`` train / rest eval. ``fov_deg``: horizontal (= vertical) field
    of view. ``supersampling``: RGB rays per pixel along each axis (labels and depth
    are always exact at pixel centres). ``depth_unit_scale_factor``: metres per unit
    of the 16-bit depth PNGs; a scene whose views reach farther than 65535 units uses
    the next coarser 1-2-5 step and records it in ``transforms.json``.
    ``ideal``/``multi``: whether to add those facade views.
    """

    resolution: int = 512
    views: int = 200
    train_fraction: float = 0.5
    fov_deg: float = 60.0
    supersampling: int = 1
    depth_unit_scale_factor: float = 0.001
    ideal: bool = True
    multi: bool = True
    orbit: OrbitConfig = field(default_factory=OrbitConfig)
    facade_views: FacadeViewConfig = field(default_factory=FacadeViewConfig)
    rgb: RgbConfig = field(default_factory=RgbConfig)

    def __post_init__(self) -> None:
        if self.resolution < 8:
            raise ValueError(f"resolution must be >= 8 pixels, got {self.resolution}")
        if self.views < 1:
            raise ValueError(f"views must be >= 1, got {self.views}")
        if not 0 <= self.train_fraction <= 1:
            raise ValueError(f"train_fraction must be in [0, 1], got {self.train_fraction}")
        if not 1 <= self.fov_deg <= 150:
            raise ValueError(f"fov_deg must be in [1, 150] degrees, got {self.fov_deg}")
        if self.supersampling < 1:
            raise ValueError(f"supersampling must be >= 1, got {self.supersampling}")
        if self.depth_unit_scale_factor <= 0:
            raise ValueError("depth_unit_scale_factor must be > 0 metres per unit")

    def intrinsics(self) -> Intrinsics:
        """Square-pixel, centred intrinsics of every view."""
        return Intrinsics.from_fov(self.resolution, self.resolution, self.fov_deg)


@dataclass(frozen=True)
class PlannedView:
    """A view to render: its split, file stem, pose (4, 4) and facade (ideal/multi only)."""

    split: Split
    name: str
    world_from_camera: np.ndarray
    facade_id: int | None = None


def plan_views(
    building: Building, raycaster: Raycaster, config: GenerateConfig, *, seed: int
) -> list[PlannedView]:
    """All views of a scene: orbit (train/eval interleaved), then ideal, then multi."""
    k = config.intrinsics()
    orbit = sample_orbit_views(building, raycaster, k, config.views, config=config.orbit, seed=seed)
    f = config.train_fraction
    views = []
    for i, pose in enumerate(orbit):
        # Interleave so train and eval both cover the whole sphere band.
        split: Split = "train" if np.floor((i + 1) * f) > np.floor(i * f) else "eval"
        views.append(PlannedView(split, f"{split}_{i:04d}", pose))
    if config.ideal:
        for i, (fid, pose) in enumerate(ideal_views(building, raycaster, k,
                                                    config=config.facade_views)):
            views.append(PlannedView("ideal", f"ideal_{i:04d}", pose, fid))
    if config.multi:
        for i, (fid, pose) in enumerate(multi_views(building, raycaster, k,
                                                    config=config.facade_views, seed=seed + 1)):
            views.append(PlannedView("multi", f"multi_{i:04d}", pose, fid))
    return views


def depth_unit_for(
    base_unit_m: float, raycaster: Raycaster, poses: list[np.ndarray]
) -> float:
    """``base_unit_m``, or the next coarser 1-2-5 step if some view could see farther than
    the 16-bit range (the bound: farthest bounding-box corner in z-depth)."""
    lo, hi = raycaster.bounds_m
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                        for z in (lo[2], hi[2])])
    far = max(float(((corners - p[:3, 3]) @ -p[:3, 2]).max()) for p in poses)
    needed = far / DEPTH_MAX_UNITS
    if needed <= base_unit_m:
        return base_unit_m
    exponent = np.floor(np.log10(needed))
    for step in (1.0, 2.0, 5.0, 10.0):
        unit = float(step * 10.0**exponent)
        if unit >= needed:
            return max(unit, base_unit_m)
    raise AssertionError("unreachable")


def generate_scene(
    building: Building, out_dir: str | Path, config: GenerateConfig, *, seed: int,
    name: str | None = None, progress: bool = True,
) -> Path:
    """Write one complete scene folder ``out_dir / name`` atomically; return its path.

    ``name`` defaults to the building id. ``seed`` fixes the cameras and the
    building's look. An existing folder of that name is replaced.

    Raises
    ------
    ValueError
        If the name is not a plain folder name or the building cannot be framed.
    """
    name = building.truth.id if name is None else name
    _check_scene_name(name)
    raycaster = Raycaster(building.mesh)
    k = config.intrinsics()
    views = plan_views(building, raycaster, config, seed=seed)
    unit = depth_unit_for(config.depth_unit_scale_factor, raycaster,
                          [v.world_from_camera for v in views])
    scene_dir = Path(out_dir) / name
    with atomic_directory(scene_dir) as tmp:
        frames = []
        for view in tqdm(views, desc=name, unit="view", disable=not progress, leave=False):
            frames.append(_render_view(tmp, raycaster, k, view, config, seed, unit))
        scene = Scene(root=tmp, frames=tuple(frames), depth_unit_scale_factor=unit,
                      extra={"generator": generator_record(config, seed)})
        write_transforms(tmp, scene)
        write_building(tmp / "building.json", building.truth)
        write_labelled_ply(tmp / "mesh.ply", building.mesh)
    return scene_dir


def generator_record(config: GenerateConfig, seed: int) -> dict[str, Any]:
    """What ``transforms.json`` records under ``generator``: config, seed, code version."""
    return {"config": _config_json(config), "seed": int(seed), "code_version": code_version()}


def scene_is_finished(scene_dir: str | Path, config: GenerateConfig, seed: int) -> bool:
    """Whether ``scene_dir`` is a finished scene made with this config and seed."""
    tf = Path(scene_dir) / "transforms.json"
    if not tf.is_file():
        return False
    try:
        made = json.loads(tf.read_text()).get("generator", {})
    except json.JSONDecodeError:
        return False
    return made.get("config") == _config_json(config) and made.get("seed") == int(seed)


def scene_seed(base_seed: int, recipe_seed: int) -> int:
    """Seed of one preset scene: mixes the run's seed with the recipe's."""
    return int(np.random.SeedSequence([int(base_seed), int(recipe_seed)]).generate_state(1)[0])


def generate_preset(
    name: str, out_root: str | Path, config: GenerateConfig, *, workers: int = 1, seed: int = 0,
    overwrite: bool = False, progress: bool = True,
) -> list[Path]:
    """Generate every building of preset ``name`` into ``out_root``; return the scene folders.

    Resumable: scenes already finished with this config and seed are skipped.
    ``workers`` processes each build and render one building at a time.

    Raises
    ------
    ValueError
        Unknown preset, ``workers < 1``, unwritable ``out_root``, a scene folder
        made with another config or seed (pass ``overwrite=True`` to replace it),
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
        if scene_is_finished(scene_dir, config, s):
            continue
        if scene_dir.exists() and not overwrite:
            raise ValueError(
                f"{scene_dir} holds a scene made with another config or seed; use a new --out "
                "or --overwrite to replace it"
            )
        todo.append((recipe, out_root, config, s))
    bar = tqdm(total=len(recipes), initial=len(recipes) - len(todo), desc=f"preset {name}",
               unit="building", disable=not progress)
    with bar:
        if workers == 1 or len(todo) <= 1:
            for job in todo:
                _generate_recipe(job, progress=progress)
                bar.update()
        else:
            _run_pool(todo, workers, bar)
    return [out_root / r.id for r in recipes]


def check_writable(folder: Path) -> None:
    """Create ``folder`` if needed and make sure files can be written there (ValueError if not)."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as exc:
        raise ValueError(
            f"cannot write to output folder {folder}: {exc.strerror or exc}; choose another --out"
        ) from exc


def _render_view(
    tmp: Path, raycaster: Raycaster, k: Intrinsics, view: PlannedView, config: GenerateConfig,
    seed: int, unit: float,
) -> Frame:
    gt, rgb = render_view(raycaster, k, view.world_from_camera, config=config.rgb, seed=seed,
                          supersampling=config.supersampling)
    paths = {folder: f"{folder}/{view.name}.png"
             for folder in ("images", "depth", "semantics", "normals", "instances")}
    write_rgb(tmp / paths["images"], rgb)
    write_depth_m(tmp / paths["depth"], gt.depth_z_m, unit)
    write_labels(tmp / paths["semantics"], gt.labels)
    write_normals(tmp / paths["normals"], gt.normals_world)
    write_facade_ids(tmp / paths["instances"], gt.facade_ids)
    return Frame(
        file_path=paths["images"], world_from_camera=view.world_from_camera, intrinsics=k,
        split=view.split, facade_id=view.facade_id, depth_file_path=paths["depth"],
        semantic_file_path=paths["semantics"], normal_file_path=paths["normals"],
        instance_file_path=paths["instances"],
    )


def _generate_recipe(job: tuple, progress: bool = False) -> Path:
    from dataset.presets import build_building

    recipe, out_root, config, s = job
    building = build_building(recipe)
    return generate_scene(building, out_root, config, seed=s, name=recipe.id, progress=progress)


def _run_pool(todo: list[tuple], workers: int, bar: tqdm) -> None:
    pool = multiprocessing.get_context("spawn").Pool(
        min(workers, len(todo)), initializer=_init_worker
    )
    try:
        for _ in pool.imap_unordered(_generate_recipe, todo):
            bar.update()
        pool.close()
    except BaseException:
        # Workers ignore Ctrl-C; SIGTERM makes each one delete its unfinished scene.
        pool.terminate()
        raise
    finally:
        pool.join()


def _init_worker() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, _exit_on_sigterm)


def _exit_on_sigterm(signum: int, frame: Any) -> None:
    raise SystemExit(128 + signum)  # unwinds atomic_directory, which removes the partial folder


def _interrupt_on_sigterm(signum: int, frame: Any) -> None:
    raise KeyboardInterrupt


def _remove_stale_partials(out_root: Path, name: str) -> None:
    """Remove temporary folders a killed run (SIGKILL, power loss) left for scene ``name``."""
    for stale in out_root.glob(f".{name}.*.partial"):
        shutil.rmtree(stale, ignore_errors=True)


def _check_scene_name(name: str) -> None:
    if not name or name.startswith(".") or "/" in name or "\\" in name or name != name.strip():
        raise ValueError(
            f"scene name {name!r} is not a plain folder name (no slashes, no leading dot)"
        )


def _config_json(config: GenerateConfig) -> dict[str, Any]:
    return json.loads(json.dumps(asdict(config)))


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
    )
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--preset", choices=PRESETS, help="built-in set of procedural buildings")
    src.add_argument("--mesh", type=Path, metavar="FILE",
                     help="your labelled mesh (.ply with per-face label, or .obj/.glb with "
                          "class-named parts), metres, z up; see docs/importing.md")
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
                   help="processes, each rendering one building at a time (default 1)")
    p.add_argument("--seed", type=int, default=0, help="seed for cameras and looks (default 0)")
    p.add_argument("--overwrite", action="store_true",
                   help="replace scenes that were made with another config or seed")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    return p.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    """CLI entry point; returns the exit code (0 ok, 2 bad input, 130 interrupted)."""
    args = _parse_args(argv)
    # `kill` (SIGTERM) stops the run as cleanly as Ctrl-C does.
    previous = signal.signal(signal.SIGTERM, _interrupt_on_sigterm)
    try:
        config = GenerateConfig(
            resolution=args.resolution, views=args.views, train_fraction=args.train_fraction,
            fov_deg=args.fov, supersampling=args.supersampling,
        )
        if args.preset is not None:
            scenes = generate_preset(args.preset, args.out, config, workers=args.workers,
                                     seed=args.seed, overwrite=args.overwrite,
                                     progress=not args.quiet)
        else:
            scenes = [_generate_mesh(args, config)]
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted: finished scenes are kept, unfinished ones were removed; "
              "run the same command again to resume", file=sys.stderr)
        return 130
    except OSError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    finally:
        signal.signal(signal.SIGTERM, previous)
    for scene in scenes:
        print(scene)
    return 0


def _generate_mesh(args: argparse.Namespace, config: GenerateConfig) -> Path:
    from dataset.importer import import_labelled_mesh

    building = import_labelled_mesh(args.mesh)
    check_writable(args.out)
    name = building.truth.id
    _remove_stale_partials(args.out, name)
    scene_dir = args.out / name
    if scene_is_finished(scene_dir, config, args.seed):
        return scene_dir
    if scene_dir.exists() and not args.overwrite:
        raise ValueError(f"{scene_dir} holds a scene made with another config or seed; use a "
                         "new --out or --overwrite to replace it")
    return generate_scene(building, args.out, config, seed=args.seed, progress=not args.quiet)


if __name__ == "__main__":
    sys.exit(main())
