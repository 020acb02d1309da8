"""The held-out designs: buildings that differ in kind from the ``paper`` preset's.

Eight designs (:mod:`dataset.families.heldout_params` lists them) built from the
same parts as the realistic family (walls with recessed openings, prisms, roofs)
and typed ``realistic`` in the truth, so tables report them in that family. Only
the ``heldout`` preset uses them: nothing is tuned on them (``docs/metrics.md``).
The seed jitters sizes around :func:`default_heldout_params`.
"""

from __future__ import annotations

from dataclasses import asdict, replace

import numpy as np

from dataset.families.building_assembly import BuildingLayout, assemble_layout
from dataset.families.heldout_params import HeldoutModel, HeldoutParams, default_heldout_params
from dataset.families.heldout_plan import bow_layout, corner_layout, sawtooth_layout
from dataset.families.heldout_recess import loggia_layout
from dataset.families.heldout_roofs import hip_layout, mansard_layout
from dataset.families.heldout_setback import setback_layout
from dataset.families.heldout_slope import slope_layout
from envelope.truth import Building

_LAYOUTS = {
    "hip": hip_layout, "mansard": mansard_layout, "setback": setback_layout,
    "loggia": loggia_layout, "corner": corner_layout, "bow": bow_layout,
    "slope": slope_layout, "sawtooth": sawtooth_layout,
}


def heldout_layout(params: HeldoutParams) -> BuildingLayout:
    """Walls, roof and attached solids of the design ``params.model``.

    Raises
    ------
    ValueError
        If openings, recesses, tiers or roof do not fit.
    """
    return _LAYOUTS[params.model](params)


def make_heldout(
    params: HeldoutParams, *, building_id: str | None = None, seed: int | None = None
) -> Building:
    """Mesh and exact truth of a held-out design (``building_id`` defaults to heldout_<model>)."""
    layout = heldout_layout(params)
    layout = replace(layout, extra={"params": asdict(params), **layout.extra})
    return assemble_layout(
        layout, building_id=building_id or f"heldout_{params.model}", building_type="realistic",
        seed=seed, name=params.model,
    )


def sample_heldout_params(rng: np.random.Generator, model: HeldoutModel) -> HeldoutParams:
    """The design's defaults with sizes jittered by a few percent (same rng -> same params)."""
    base = default_heldout_params(model)
    for _ in range(100):
        scale = rng.uniform(0.95, 1.05, size=9)
        try:
            params = replace(
                base,
                width_m=base.width_m * scale[0],
                depth_m=base.depth_m * scale[1],
                floor_height_m=base.floor_height_m * rng.uniform(0.98, 1.03),
                roof_m=base.roof_m * scale[2],
                window_width_m=base.window_width_m * scale[3],
                window_height_m=base.window_height_m * scale[4],
                reveal_m=rng.uniform(0.05, 0.09),
                setback_m=base.setback_m * scale[5],
                recess_m=base.recess_m * scale[6],
                corner_deg=base.corner_deg + rng.uniform(-5.0, 5.0),
                radius_m=base.radius_m * rng.uniform(0.9, 1.1),
                rise_m=base.rise_m * scale[7],
                step_m=base.step_m * scale[8],
            )
            heldout_layout(params)
            return params
        except ValueError:
            continue
    raise RuntimeError(f"could not sample parameters for the held-out design {model!r}")
