"""Skyscraper family: a rectangular tower with a regular window grid and a flat roof.

Footprint ``width_m`` (x) by ``depth_m`` (y), centred on the origin. Facades:
1 south (-y, holds the entrance door), 2 east (+x), 3 north (+y), 4 west (-x).
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

# Ranges of the family (issue 2). 22 storeys of >= 2.7 m cannot stay below 46 m, so the
# sampler caps the storey count by the height range (see docs/buildings.md).
FLOORS_RANGE = (9, 22)
HEIGHT_RANGE_M = (20.0, 46.0)
FOOTPRINT_RANGE_M2 = (27.0, 80.0)
WWR_RANGE = (0.15, 0.41)


@dataclass(frozen=True)
class SkyscraperParams:
    """Parameters of one skyscraper, metres. ``columns_front`` windows per floor on facades
    1 and 3 (along x), ``columns_side`` on facades 2 and 4 (along y)."""

    width_m: float = 7.0
    depth_m: float = 6.0
    floors: int = 10
    floor_height_m: float = 2.8
    columns_front: int = 3
    columns_side: int = 2
    windows: WindowSpec = field(default_factory=WindowSpec)
    roof: RoofSpec = field(default_factory=RoofSpec)

    def __post_init__(self) -> None:
        if self.width_m <= 0 or self.depth_m <= 0:
            raise ValueError(
                f"footprint must be > 0 m each way, got {self.width_m} x {self.depth_m}"
            )
        skyscraper_walls(self)  # raises ValueError when the grid or door does not fit

    @property
    def height_m(self) -> float:
        return self.floors * self.floor_height_m + self.roof.above_floors_m


def skyscraper_footprint(params: SkyscraperParams) -> np.ndarray:
    """(4, 2) counter-clockwise footprint, world x/y metres, centred on the origin."""
    x, y = params.width_m / 2, params.depth_m / 2
    return np.array([[-x, -y], [x, -y], [x, y], [-x, y]])


def skyscraper_walls(params: SkyscraperParams) -> list[WallSpec]:
    """The four walls with windows and door
    (:func:`dataset.families.grid_prism.grid_prism_walls`)."""
    cf, cs = params.columns_front, params.columns_side
    return grid_prism_walls(
        skyscraper_footprint(params),
        floors=params.floors,
        floor_height_m=params.floor_height_m,
        columns=(cf, cs, cf, cs),
        windows=params.windows,
        door_edges=(0,),
        roof=params.roof,
    )


def make_skyscraper(
    params: SkyscraperParams, *, building_id: str = "skyscraper", seed: int | None = None
) -> Building:
    """Mesh and exact truth of a skyscraper."""
    return grid_prism_building(
        skyscraper_footprint(params),
        skyscraper_walls(params),
        floors=params.floors,
        floor_height_m=params.floor_height_m,
        roof=params.roof,
        building_id=building_id,
        building_type="skyscraper",
        seed=seed,
        params=asdict(params),
    )


def sample_skyscraper_params(rng: np.random.Generator) -> SkyscraperParams:
    """Random parameters inside the family's ranges (floors, height, footprint, WWR)."""
    for _ in range(100):
        floor_h = rng.uniform(2.7, 3.0)
        if rng.random() < 0.5:
            roof = RoofSpec("parapet", parapet_height_m=rng.uniform(0.8, 1.2),
                            parapet_thickness_m=rng.uniform(0.2, 0.3))
        else:
            roof = RoofSpec("overhang", overhang_m=rng.uniform(0.3, 0.8),
                            thickness_m=rng.uniform(0.25, 0.4))
        max_floors = min(FLOORS_RANGE[1], int((HEIGHT_RANGE_M[1] - 0.5 - roof.above_floors_m)
                                             // floor_h))
        floors = int(rng.integers(FLOORS_RANGE[0], max_floors + 1))
        area = rng.uniform(FOOTPRINT_RANGE_M2[0] + 1, FOOTPRINT_RANGE_M2[1] - 1)
        aspect = rng.uniform(1.0, 1.6)
        width, depth = np.sqrt(area * aspect), np.sqrt(area / aspect)
        margin = rng.uniform(0.4, 0.8)
        bay = rng.uniform(1.8, 3.2)
        cf = max(1, round((width - 2 * margin) / bay))
        cs = max(1, round((depth - 2 * margin) / bay))
        sill = rng.uniform(0.6, 0.9)
        win_h = rng.uniform(1.2, min(1.8, floor_h - sill - 0.3))
        # Window width that gives a target WWR, ignoring the door and the roof band.
        target = rng.uniform(WWR_RANGE[0] + 0.02, WWR_RANGE[1] - 0.02)
        gross = 2 * (width + depth) * floors * floor_h
        n_windows = 2 * (cf + cs) * floors
        max_w = min((width - 2 * margin) / cf, (depth - 2 * margin) / cs) - 0.2
        win_w = float(np.clip(target * gross / (n_windows * win_h), 0.5, max_w))
        windows = WindowSpec(
            window_width_m=win_w, window_height_m=win_h, sill_height_m=sill, margin_m=margin,
            reveal_m=rng.uniform(0.05, 0.08), door_width_m=rng.uniform(1.0, min(1.8, width - 2)),
            door_height_m=rng.uniform(2.1, 2.3),
        )
        try:
            params = SkyscraperParams(width, depth, floors, floor_h, cf, cs, windows, roof)
        except ValueError:
            continue
        if WWR_RANGE[0] < grid_prism_wwr(skyscraper_walls(params)) < WWR_RANGE[1]:
            return params
    raise RuntimeError("could not sample skyscraper parameters inside the family's ranges")
