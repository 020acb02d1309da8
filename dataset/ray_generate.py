"""Render a preset's buildings on a Ray cluster: one task per building, no shared folder.

Each task builds its building from the recipe, renders the scene folder into
a temporary folder on the worker and returns it packed
(:mod:`dataset.executors.folder_pack`); this process unpacks it into ``out_root``
atomically, so a folder with the final name is always finished, and a rerun
skips it. A building that fails (it cannot be framed) stops the run as with
the local pool: the tasks not yet collected are cancelled.
"""

from __future__ import annotations

import tempfile
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from dataset.core.atomic import atomic_directory
from dataset.executors.folder_pack import pack_folder, unpack_folder
from dataset.executors.ray_tasks import RayConfig, TaskLost, TaskResources, ray_session, run_tasks
from dataset.scenes.scene_writer import GenerateConfig, generate_scene

if TYPE_CHECKING:
    from dataset.presets import BuildingRecipe

RENDER_RESOURCES = TaskResources(cpus=1.0)  # embree renders a building on one core here


def generate_on_ray(
    recipes: Sequence[BuildingRecipe], out_root: Path, config: GenerateConfig, seeds: Sequence[int],
    inputs: Sequence[dict], ray: RayConfig,
) -> Iterator[Path]:
    """Render ``recipes[i]`` with ``seeds[i]`` into ``out_root / recipe.id`` (``inputs[i]``
    goes into its provenance record); yield each scene folder as it is written, in the order
    the tasks finish.

    Raises
    ------
    ValueError
        If a building fails to render (its reason), or Ray cannot start.
    """
    with ray_session(ray):
        calls = [((recipe, config, seed, made_from), RENDER_RESOURCES)
                 for recipe, seed, made_from in zip(recipes, seeds, inputs)]
        for i, value in run_tasks(_render_packed, calls, max_retries=ray.max_retries):
            if isinstance(value, TaskLost):
                raise ValueError(f"building {recipes[i].id}: {value.reason}")
            with atomic_directory(out_root / recipes[i].id) as tmp:
                unpack_folder(value, tmp)
            yield out_root / recipes[i].id


def _render_packed(
    recipe: BuildingRecipe, config: GenerateConfig, seed: int, inputs: dict
) -> bytes:
    """On a worker: the recipe's scene folder, rendered in a temporary folder, packed."""
    from dataset.presets import build_building

    with tempfile.TemporaryDirectory(prefix="envelope-bench-") as tmp:
        scene_dir = generate_scene(build_building(recipe), tmp, config, seed=seed,
                                   name=recipe.id, progress=False, inputs=inputs)
        return pack_folder(scene_dir)
