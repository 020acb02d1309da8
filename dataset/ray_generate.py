"""Render a preset's buildings on a Ray cluster: one task per building, no shared folder.

Each task builds its building from its entry (:class:`dataset.importers.source.BuildingEntry`:
a preset's recipe, nothing read from this machine's files), renders the scene folder into
a temporary folder on the worker and returns it packed
(:mod:`envelope.executors.folder_pack`); this process unpacks it into ``out_root``
atomically, so a folder with the final name is always finished, and a rerun
skips it. A building that fails (it cannot be framed) stops the run as with
the local pool: the tasks not yet collected are cancelled.
"""

from __future__ import annotations

import tempfile
from collections.abc import Iterator, Sequence
from pathlib import Path

from dataset.importers.source import BuildingEntry
from dataset.scenes.scene_writer import GenerateConfig, generate_scene
from envelope.atomic import atomic_directory
from envelope.executors.folder_pack import pack_folder, unpack_folder
from envelope.executors.ray_tasks import RayConfig, TaskLost, TaskResources, ray_session, run_tasks

RENDER_RESOURCES = TaskResources(cpus=1.0)  # embree renders a building on one core here


def generate_on_ray(
    entries: Sequence[BuildingEntry], out_root: Path, config: GenerateConfig,
    seeds: Sequence[int], inputs: Sequence[dict], ray: RayConfig,
) -> Iterator[Path]:
    """Render ``entries[i]`` with ``seeds[i]`` into ``out_root / entry.name`` (``inputs[i]``
    goes into its provenance record); yield each scene folder as it is written, in the order
    the tasks finish.

    Raises
    ------
    ValueError
        If a building fails to render (its reason), or Ray cannot start.
    """
    with ray_session(ray):
        calls = [((entry, config, seed, made_from), RENDER_RESOURCES)
                 for entry, seed, made_from in zip(entries, seeds, inputs)]
        for i, value in run_tasks(_render_packed, calls, max_retries=ray.max_retries):
            if isinstance(value, TaskLost):
                raise ValueError(f"building {entries[i].name}: {value.reason}")
            with atomic_directory(out_root / entries[i].name) as tmp:
                unpack_folder(value, tmp)
            yield out_root / entries[i].name


def _render_packed(
    entry: BuildingEntry, config: GenerateConfig, seed: int, inputs: dict
) -> bytes:
    """On a worker: the entry's scene folder, rendered in a temporary folder, packed."""
    with tempfile.TemporaryDirectory(prefix="envelope-bench-") as tmp:
        scene_dir = generate_scene(entry.build(), tmp, config, seed=seed, name=entry.name,
                                   progress=False, inputs=inputs)
        return pack_folder(scene_dir)
