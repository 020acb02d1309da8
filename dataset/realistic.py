"""Realistic family: four named models with the complexity of real buildings.

- ``house``: residential house, gable roof, front and back doors, a chimney
  through the roof, windows of three sizes (:mod:`dataset.realistic_house`);
- ``rounded``: a block whose east end is a half-round, faceted curved facade
  (:mod:`dataset.realistic_rounded`);
- ``balcony_a``: a block with one balcony per bay on the long facades;
- ``balcony_b``: a block with continuous balconies along the long facades
  (both :mod:`dataset.realistic_balcony`).

All models share :class:`RealisticParams`; each reads the fields it needs and
documents how. The seed only jitters sizes around :func:`default_realistic_params`.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace
from typing import Literal

import numpy as np

from dataset.building_assembly import BuildingLayout, assemble_layout
from dataset.realistic_balcony import balcony_layout
from dataset.realistic_house import house_layout
from dataset.realistic_rounded import rounded_layout
from dataset.truth import Building

RealisticModel = Literal["house", "rounded", "balcony_a", "balcony_b"]
REALISTIC_MODELS: tuple[str, ...] = ("house", "rounded", "balcony_a", "balcony_b")

FLOORS_RANGE = (2, 7)
HEIGHT_RANGE_M = (14.0, 25.0)
FOOTPRINT_RANGE_M2 = (90.0, 215.0)
WWR_RANGE = (0.10, 0.20)


@dataclass(frozen=True)
class RealisticParams:
    """Parameters of one realistic model, metres.

    ``width_m`` is the x extent and ``depth_m`` the y extent of the footprint (for
    ``rounded`` the half-round end's diameter is ``depth_m``). ``roof_m`` is the
    ridge rise above the eaves for ``house`` and the parapet height otherwise.
    ``window_width_m``/``window_height_m`` size the typical window; models derive
    their other openings from it. ``balcony_depth_m`` is used by the balcony models.
    """

    model: RealisticModel = "house"
    width_m: float = 12.0
    depth_m: float = 9.0
    floors: int = 3
    floor_height_m: float = 2.9
    roof_m: float = 5.8
    window_width_m: float = 1.2
    window_height_m: float = 1.3
    reveal_m: float = 0.06
    balcony_depth_m: float = 1.2

    def __post_init__(self) -> None:
        if self.model not in REALISTIC_MODELS:
            raise ValueError(
                f"unknown realistic model {self.model!r}; "
                f"choose one of {', '.join(REALISTIC_MODELS)}"
            )
        if self.floors < 1:
            raise ValueError(f"floors must be >= 1, got {self.floors}; a building needs a storey")
        for name in ("width_m", "depth_m", "floor_height_m", "roof_m", "window_width_m",
                     "window_height_m", "reveal_m", "balcony_depth_m"):
            if getattr(self, name) <= 0:
                raise ValueError(f"{name} must be > 0, got {getattr(self, name)}")
        realistic_layout(self)  # raises ValueError when openings, balconies or roof do not fit


def default_realistic_params(model: RealisticModel) -> RealisticParams:
    """The nominal parameters of a model (the seed jitters around these)."""
    if model == "house":
        return RealisticParams("house", floor_height_m=2.95)
    if model == "rounded":
        return RealisticParams("rounded", 17.0, 11.0, 5, 3.1, 1.0, 1.3, 1.5)
    if model == "balcony_a":
        return RealisticParams("balcony_a", 14.0, 10.0, 6, 3.0, 1.0, 1.2, 1.4, balcony_depth_m=1.2)
    if model == "balcony_b":
        return RealisticParams("balcony_b", 16.0, 11.5, 7, 3.0, 1.0, 1.2, 1.4, balcony_depth_m=1.6)
    raise ValueError(
        f"unknown realistic model {model!r}; choose one of {', '.join(REALISTIC_MODELS)}"
    )


def realistic_layout(params: RealisticParams) -> BuildingLayout:
    """Walls, roof and attached solids of the model ``params.model``."""
    if params.model == "house":
        return house_layout(params)
    if params.model == "rounded":
        return rounded_layout(params)
    return balcony_layout(params, continuous=params.model == "balcony_b")


def make_realistic(
    params: RealisticParams, *, building_id: str | None = None, seed: int | None = None
) -> Building:
    """Mesh and exact truth of a realistic model (``building_id`` defaults to realistic_<model>)."""
    layout = realistic_layout(params)
    layout = replace(layout, extra={"params": asdict(params), **layout.extra})
    return assemble_layout(
        layout,
        building_id=building_id or f"realistic_{params.model}",
        building_type="realistic",
        seed=seed,
        name=params.model,
    )


def sample_realistic_params(rng: np.random.Generator, model: RealisticModel) -> RealisticParams:
    """The model's defaults with sizes jittered by a few percent (same rng -> same params)."""
    base = default_realistic_params(model)
    for _ in range(100):
        scale = rng.uniform(0.95, 1.05, size=6)
        try:
            return replace(
                base,
                width_m=base.width_m * scale[0],
                depth_m=base.depth_m * scale[1],
                floor_height_m=base.floor_height_m * rng.uniform(0.98, 1.03),
                roof_m=base.roof_m * scale[2],
                window_width_m=base.window_width_m * scale[3],
                window_height_m=base.window_height_m * scale[4],
                reveal_m=rng.uniform(0.05, 0.08),
                balcony_depth_m=base.balcony_depth_m * scale[5],
            )
        except ValueError:
            continue
    raise RuntimeError(f"could not sample parameters for the realistic model {model!r}")
