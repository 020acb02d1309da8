"""A prism building with a regular window grid per facade, doors and a flat roof.

The shared machinery of the skyscraper and L-shaped families: every footprint
edge is one facade (ids 1..n in edge order) with ``columns[i]`` windows per
floor; chosen edges get a centred door on the ground floor (windows that would
touch it are left out); the roof has a parapet or an overhang
(:mod:`dataset.families.prism`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any, Literal

import numpy as np

from dataset.families.building_assembly import assemble_building, facade_truths
from dataset.families.facade_geometry import Opening, WallSpec, drop_near, window_grid
from dataset.families.prism import ground_face, overhang_roof_faces, parapet_roof_faces, prism_walls
from envelope.truth import Building, BuildingType
from envelope.wwr import ClassAreas

RoofKind = Literal["parapet", "overhang"]


@dataclass(frozen=True)
class RoofSpec:
    """Flat roof: a parapet (walls rise above the roof) or an overhanging slab, metres."""

    kind: RoofKind = "parapet"
    parapet_height_m: float = 1.0
    parapet_thickness_m: float = 0.25
    overhang_m: float = 0.5
    thickness_m: float = 0.3

    def __post_init__(self) -> None:
        if self.kind not in ("parapet", "overhang"):
            raise ValueError(f"roof kind must be 'parapet' or 'overhang', got {self.kind!r}")
        for name in ("parapet_height_m", "parapet_thickness_m", "overhang_m", "thickness_m"):
            if getattr(self, name) <= 0:
                raise ValueError(f"roof {name} must be > 0, got {getattr(self, name)}")

    @property
    def above_floors_m(self) -> float:
        """Height of the roof construction above the top floor (parapet or slab)."""
        return self.parapet_height_m if self.kind == "parapet" else self.thickness_m


@dataclass(frozen=True)
class WindowSpec:
    """Size and placement of the grid windows and of the ground-floor doors, metres."""

    window_width_m: float = 1.2
    window_height_m: float = 1.4
    sill_height_m: float = 0.9
    margin_m: float = 0.6
    reveal_m: float = 0.06
    door_width_m: float = 1.2
    door_height_m: float = 2.2
    door_threshold_m: float = 0.1
    door_reveal_m: float = 0.08


def grid_prism_walls(
    footprint_xy: np.ndarray,
    *,
    floors: int,
    floor_height_m: float,
    columns: tuple[int, ...],
    windows: WindowSpec,
    door_edges: tuple[int, ...],
    roof: RoofSpec,
) -> list[WallSpec]:
    """Walls (facade i + 1 over edge i) with their window grids and doors.

    Raises
    ------
    ValueError
        If floors < 1, the column count does not match the edges, or any window or door
        does not fit its wall.
    """
    if floors < 1:
        raise ValueError(f"floors must be >= 1, got {floors}; a building needs a storey")
    if floor_height_m <= 0:
        raise ValueError(f"floor height must be > 0 m, got {floor_height_m}")
    n = len(footprint_xy)
    if len(columns) != n:
        raise ValueError(f"need one column count per footprint edge ({n}), got {len(columns)}")
    if any(e < 0 or e >= n for e in door_edges):
        raise ValueError(f"door edges {door_edges} must index footprint edges 0..{n - 1}")
    w = windows
    if w.door_threshold_m + w.door_height_m > floor_height_m - 0.05:
        raise ValueError(
            f"door ({w.door_height_m} m on a {w.door_threshold_m} m threshold) is taller than "
            f"the ground floor ({floor_height_m} m); use a lower door or taller floors"
        )
    wall_height = floors * floor_height_m + (roof.parapet_height_m if roof.kind == "parapet" else 0)
    lengths = np.linalg.norm(np.roll(footprint_xy, -1, axis=0) - footprint_xy, axis=1)
    openings: list[list[Opening]] = []
    for i, (length, cols) in enumerate(zip(lengths, columns)):
        grid = window_grid(
            float(length), floors, floor_height_m, columns=cols,
            window_width_m=w.window_width_m, window_height_m=w.window_height_m,
            sill_height_m=w.sill_height_m, margin_m=w.margin_m, depth_m=w.reveal_m,
        )
        if i in door_edges:
            centre = float(length) / 2
            door = Opening(
                "door", centre - w.door_width_m / 2, w.door_threshold_m,
                centre + w.door_width_m / 2, w.door_threshold_m + w.door_height_m, w.door_reveal_m,
            )
            grid = [door, *drop_near(grid, [door])]
        openings.append(grid)
    return prism_walls(footprint_xy, wall_height, list(range(1, n + 1)), openings)


def grid_prism_wwr(walls: list[WallSpec]) -> float:
    """Whole-building WWR of walls from their parameters (cheap: no mesh)."""
    facades = facade_truths(walls)
    return ClassAreas(*(sum(getattr(f, f"{c}_area_m2") for f in facades)
                        for c in ("window", "wall", "door"))).wwr


def grid_prism_building(
    footprint_xy: np.ndarray,
    walls: list[WallSpec],
    *,
    floors: int,
    floor_height_m: float,
    roof: RoofSpec,
    building_id: str,
    building_type: BuildingType,
    seed: int | None,
    params: dict[str, Any],
) -> Building:
    """Close :func:`grid_prism_walls` with ground and roof and attach the truth."""
    top = floors * floor_height_m
    if roof.kind == "parapet":
        roof_faces = parapet_roof_faces(
            footprint_xy, top, roof.parapet_height_m, roof.parapet_thickness_m
        )
    else:
        roof_faces = overhang_roof_faces(footprint_xy, top, roof.overhang_m, roof.thickness_m)
    return assemble_building(
        building_id=building_id,
        building_type=building_type,
        seed=seed,
        floors=floors,
        height_m=top + roof.above_floors_m,
        footprint_xy=footprint_xy,
        walls=walls,
        other_faces=[ground_face(footprint_xy), *roof_faces],
        extra={"params": params, "roof": asdict(roof)},
    )
