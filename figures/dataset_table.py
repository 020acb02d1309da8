"""Table 1: dataset statistics per building family, from the scenes' building.json files."""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

from envelope.truth import BuildingTruth, read_building
from figures.style import MissingInput
from metrics.report.tables import Table
from metrics.score.aggregate import ALL_FAMILIES, family_rank

TABLE1_NAME = "table1_dataset"


def read_truths(scene_dirs: Sequence[Path]) -> list[tuple[Path, BuildingTruth]]:
    """(scene folder, truth) of every scene with a readable building.json."""
    out = []
    for scene_dir in scene_dirs:
        try:
            out.append((scene_dir, read_building(scene_dir / "building.json")))
        except ValueError:
            continue  # scenes without truth (a user's photos) have no statistics
    return out


def count_images(scene_dir: Path) -> int:
    """Number of frames (images) in a scene's transforms.json; 0 when there is none."""
    try:
        return len(json.loads((scene_dir / "transforms.json").read_text())["frames"])
    except (OSError, ValueError, KeyError):
        return 0


def table1_dataset(truths: Sequence[tuple[Path, BuildingTruth]]) -> Table:
    """Per family: buildings, images, and the ranges of floors, footprint, height and WWR.

    Raises
    ------
    MissingInput
        If no scene has a ground truth.
    """
    if not truths:
        raise MissingInput("no scene with a building.json: nothing to describe in Table 1")
    families = sorted({t.type for _, t in truths}, key=family_rank)
    rows = []
    for family in [*families, ALL_FAMILIES] if len(families) > 1 else families:
        mine = [(d, t) for d, t in truths if family in (ALL_FAMILIES, t.type)]
        rows.append((
            family,
            len(mine),
            sum(count_images(d) for d, _ in mine),
            _range([t.floors for _, t in mine], "{:d}"),
            _range([t.footprint_area_m2 for _, t in mine], "{:.0f}"),
            _range([t.height_m for _, t in mine], "{:.1f}"),
            _range([t.wwr for _, t in mine], "{:.2f}"),
        ))
    return Table(
        name=TABLE1_NAME,
        title="Benchmark statistics per building family (ranges are min–max)",
        columns=("Family", "Buildings", "Images", "Floors", "Footprint (m²)", "Height (m)",
                 "WWR"),
        keys=("family", "buildings", "images", "floors", "footprint_m2", "height_m", "wwr"),
        rows=tuple(rows),
    )


def _range(values: Sequence[float], fmt: str) -> str:
    lo, hi = min(values), max(values)
    return fmt.format(lo) if lo == hi else f"{fmt.format(lo)}–{fmt.format(hi)}"
