"""Comparisons on degraded inputs (``python -m metrics.compare --degrade NAME[:SEVERITY],...``).

The scenes are degraded once into a cache folder next to the results
(``<data>-degraded/<key>/<scene>``, see :mod:`dataset.degrade.scene_copy`);
methods run on that copy unchanged, their results go to
``<results>/degraded/<key>`` and carry the specs in their config under
``degradation`` (so a result made under other specs is never reused); the
truth is the original's (the copy's ``building.json`` is a hard link to it).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

from tqdm import tqdm

from dataset.degrade.scene_copy import degrade_scene
from dataset.degrade.spec import DegradeSpec, specs_key
from envelope.scenes.scene import find_scene_folders
from metrics.run.runner import MethodSpec

CONFIG_KEY = "degradation"


@dataclass(frozen=True)
class DegradedRun:
    """Where a comparison under ``specs`` reads scenes and writes results and outputs."""

    data: Path
    results: Path
    out: Path


def degraded_run(data: Path, results: Path, out: Path,
                 specs: tuple[DegradeSpec, ...]) -> DegradedRun:
    """Degrade every scene of ``data`` (reusing finished copies) and name the folders."""
    key = specs_key(specs)
    cache = data.with_name(f"{data.name}-degraded") / key
    scenes = find_scene_folders(data, with_images=True)
    for scene_dir in tqdm(scenes, desc=f"degrade {key}", unit="scene", leave=False):
        degrade_scene(scene_dir, cache, specs)
    return DegradedRun(cache, results / "degraded" / key, out.with_name(f"{out.name}-{key}"))


def with_degradation(specs: Sequence[MethodSpec],
                     degradation: tuple[DegradeSpec, ...]) -> list[MethodSpec]:
    """The same methods, the configs their results record carrying the specs."""
    record = [s.to_json() for s in degradation]
    return [replace(s, conditions={**s.conditions, CONFIG_KEY: record}) for s in specs]
