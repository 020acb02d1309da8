"""Realistic family: four named models with the complexity of real buildings.

- ``house``: residential house, gable roof, front and back doors, a chimney
  through the roof, windows of three sizes (:mod:`dataset.families.realistic_house`);
- ``rounded``: a block whose east end is a half-round, faceted curved facade
  (:mod:`dataset.families.realistic_rounded`);
- ``balcony_a``: a block with one balcony per bay on the long facades;
- ``balcony_b``: a block with continuous balconies along the long facades
  (both :mod:`dataset.families.realistic_balcony`).

All models share :class:`RealisticParams`; each reads the fields it needs and
documents how. The seed only jitters sizes around :func:`default_realistic_params`.
"""

from __future__ import annotations

from dataclasses import asdict, replace

import numpy as np

from dataset.families.building_assembly import BuildingLayout, assemble_layout
from dataset.families.realistic_balcony import balcony_layout
from dataset.families.realistic_house import house_layout
from dataset.families.realistic_params import (
    RealisticModel,
    RealisticParams,
    default_realistic_params,
)
from dataset.families.realistic_rounded import rounded_layout
from envelope.truth import Building

FLOORS_RANGE = (2, 7)
HEIGHT_RANGE_M = (14.0, 25.0)
FOOTPRINT_RANGE_M2 = (90.0, 215.0)
WWR_RANGE = (0.10, 0.20)


def realistic_layout(params: RealisticParams) -> BuildingLayout:
    """Walls, roof and attached solids of the model ``params.model``.

    Raises
    ------
    ValueError
        If openings, balconies or roof do not fit.
    """
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
            params = replace(
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
            realistic_layout(params)
            return params
        except ValueError:
            continue
    raise RuntimeError(f"could not sample parameters for the realistic model {model!r}")
