"""L-shaped family: two wings forming an L (six facades, one concave corner).

In plan, a ``length_x_m`` by ``wing_y_m`` wing along x and a ``wing_x_m`` by
``length_y_m`` wing along y share the corner at the origin's south-west; the
footprint's bounding box is then centred on the origin. Counter-clockwise
corners: (0, 0), (Lx, 0), (Lx, wy), (wx, wy) (the concave corner), (wx, Ly),
(0, Ly). Facades 1..6 follow the edges: 1 south (door), 2 east end of the x
wing, 3 inner north-facing (door), 4 inner east-facing, 5 north end of the y
wing, 6 west.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np

from dataset.families.facade_geometry import WallSpec
from dataset.families.grid_prism import (
    RoofSpec,
    WindowSpec,
    grid_prism_building,
    grid_prism_walls,
    grid_prism_wwr,
)
from envelope.truth import Building

FLOORS_RANGE = (4, 6)
HEIGHT_RANGE_M = (10.0, 14.0)
FOOTPRINT_RANGE_M2 = (117.0, 218.0)
WWR_RANGE = (0.16, 0.32)
MIN_INNER_FACADE_M = 3.0
"""Shortest inner (concave-corner) facade: each wing must stick out at least this far."""


@dataclass(frozen=True)
class LShapedParams:
    """Parameters of one L-shaped building, metres; ``columns`` = windows per floor per facade."""

    length_x_m: float = 16.0
    length_y_m: float = 14.0
    wing_x_m: float = 7.0
    wing_y_m: float = 7.0
    floors: int = 4
    floor_height_m: float = 2.8
    columns: tuple[int, int, int, int, int, int] = (5, 2, 3, 2, 2, 5)
    windows: WindowSpec = field(default_factory=WindowSpec)
    roof: RoofSpec = field(default_factory=RoofSpec)

    def __post_init__(self) -> None:
        object.__setattr__(self, "columns", tuple(int(c) for c in self.columns))
        if min(self.wing_x_m, self.wing_y_m) <= 0:
            raise ValueError(f"wing widths must be > 0 m, got {self.wing_x_m}, {self.wing_y_m}")
        if (
            self.length_x_m < self.wing_x_m + MIN_INNER_FACADE_M
            or self.length_y_m < self.wing_y_m + MIN_INNER_FACADE_M
        ):
            raise ValueError(
                f"each wing must stick out >= {MIN_INNER_FACADE_M} m past the other: need "
                f"length_x > wing_x + {MIN_INNER_FACADE_M} and length_y > wing_y + "
                f"{MIN_INNER_FACADE_M}, got {self.length_x_m}, {self.wing_x_m}, "
                f"{self.length_y_m}, {self.wing_y_m}"
            )
        l_shaped_walls(self)  # raises ValueError when a grid or door does not fit

    @property
    def height_m(self) -> float:
        return self.floors * self.floor_height_m + self.roof.above_floors_m

    @property
    def footprint_area_m2(self) -> float:
        return self.length_x_m * self.wing_y_m + self.wing_x_m * (self.length_y_m - self.wing_y_m)


def l_shaped_footprint(params: LShapedParams) -> np.ndarray:
    """(6, 2) counter-clockwise footprint, world x/y metres, bounding box centred on the origin."""
    lx, ly, wx, wy = params.length_x_m, params.length_y_m, params.wing_x_m, params.wing_y_m
    corners = np.array([[0, 0], [lx, 0], [lx, wy], [wx, wy], [wx, ly], [0, ly]], dtype=float)
    return corners - np.array([lx / 2, ly / 2])


def l_shaped_walls(params: LShapedParams) -> list[WallSpec]:
    """The six walls with windows and doors
    (:func:`dataset.families.grid_prism.grid_prism_walls`)."""
    return grid_prism_walls(
        l_shaped_footprint(params),
        floors=params.floors,
        floor_height_m=params.floor_height_m,
        columns=params.columns,
        windows=params.windows,
        door_edges=(0, 2),
        roof=params.roof,
    )


def make_l_shaped(
    params: LShapedParams, *, building_id: str = "l_shaped", seed: int | None = None
) -> Building:
    """Mesh and exact truth of an L-shaped building."""
    return grid_prism_building(
        l_shaped_footprint(params),
        l_shaped_walls(params),
        floors=params.floors,
        floor_height_m=params.floor_height_m,
        roof=params.roof,
        building_id=building_id,
        building_type="l_shaped",
        seed=seed,
        params=asdict(params),
    )


def sample_l_shaped_params(rng: np.random.Generator) -> LShapedParams:
    """Random parameters inside the family's ranges (floors, height, footprint, WWR)."""
    for _ in range(200):
        floors = int(rng.integers(FLOORS_RANGE[0], FLOORS_RANGE[1] + 1))
        if rng.random() < 0.5:
            roof = RoofSpec("parapet", parapet_height_m=rng.uniform(0.5, 0.9),
                            parapet_thickness_m=rng.uniform(0.2, 0.3))
        else:
            roof = RoofSpec("overhang", overhang_m=rng.uniform(0.3, 0.8),
                            thickness_m=rng.uniform(0.25, 0.35))
        # The height range forces low storeys for six floors (2.2 m; see docs/buildings.md).
        lo = max(2.2, (HEIGHT_RANGE_M[0] + 0.2 - roof.above_floors_m) / floors)
        hi = min(3.0, (HEIGHT_RANGE_M[1] - 0.2 - roof.above_floors_m) / floors)
        if lo > hi:
            continue
        floor_h = rng.uniform(lo, hi)
        wx, wy = rng.uniform(6.0, 9.0, size=2)
        lx, ly = rng.uniform(12.0, 20.0, size=2)
        area = lx * wy + wx * (ly - wy)
        if not FOOTPRINT_RANGE_M2[0] + 2 < area < FOOTPRINT_RANGE_M2[1] - 2:
            continue
        margin = rng.uniform(0.5, 1.0)
        bay = rng.uniform(2.2, 3.5)
        lengths = (lx, wy, lx - wx, ly - wy, wx, ly)
        columns = tuple(max(1, round((x - 2 * margin) / bay)) for x in lengths)
        sill = rng.uniform(0.5, 0.8)
        win_h = rng.uniform(1.0, min(1.5, floor_h - sill - 0.25))
        target = rng.uniform(WWR_RANGE[0] + 0.02, WWR_RANGE[1] - 0.02)
        gross = 2 * (lx + ly) * floors * floor_h
        n_windows = sum(columns) * floors
        max_w = min((x - 2 * margin) / c for x, c in zip(lengths, columns)) - 0.2
        win_w = float(np.clip(target * gross / (n_windows * win_h), 0.5, max_w))
        door_h = min(rng.uniform(1.95, 2.2), floor_h - 0.2)
        windows = WindowSpec(
            window_width_m=win_w, window_height_m=win_h, sill_height_m=sill, margin_m=margin,
            reveal_m=rng.uniform(0.05, 0.08), door_width_m=rng.uniform(1.0, 1.6),
            door_height_m=door_h, door_threshold_m=0.1,
        )
        try:
            params = LShapedParams(lx, ly, wx, wy, floors, floor_h, columns, windows, roof)
        except ValueError:
            continue
        if WWR_RANGE[0] < grid_prism_wwr(l_shaped_walls(params)) < WWR_RANGE[1]:
            return params
    raise RuntimeError("could not sample L-shaped parameters inside the family's ranges")
