"""The held-out designs' parameters: one record for all eight designs, and their nominal values.

The designs differ from the ``paper`` preset's realistic models in kind, not by
jitter (``docs/buildings.md``, "Held-out designs"):

- ``hip``: a house under a hip roof with an overhanging roof slab;
- ``mansard``: a block under a mansard roof (steep lower slopes, flat top);
- ``setback``: a tower of three tiers, each set back on every side (flat terraces);
- ``loggia``: a block with loggias (recessed balconies) above a covered passage;
- ``corner``: a trapezoid block with a 60° and a 120° corner;
- ``bow``: a block whose front is one convex curved facade of large radius;
- ``slope``: a block on ground rising towards its back facade;
- ``sawtooth``: a block whose south-east side steps in many small facades.

Each design reads the fields it needs (the field docs say which);
:func:`dataset.families.heldout.heldout_layout` checks that everything fits.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

HeldoutModel = Literal["hip", "mansard", "setback", "loggia", "corner", "bow", "slope", "sawtooth"]
HELDOUT_MODELS: tuple[str, ...] = (
    "hip", "mansard", "setback", "loggia", "corner", "bow", "slope", "sawtooth")


@dataclass(frozen=True)
class HeldoutParams:
    """Parameters of one held-out design, metres and degrees.

    ``width_m`` is the x extent and ``depth_m`` the y extent of the footprint's
    bounding box; ``floors`` storeys of ``floor_height_m``. ``roof_m``: the ridge
    rise (``hip``), the mansard's height (``mansard``), else the parapet height.
    ``window_width_m``/``window_height_m`` size the typical window; ``reveal_m`` its
    recess. Design-specific: ``setback_m`` (``setback``: inset of each tier);
    ``recess_m`` (``loggia``: depth of the loggias and the passage); ``corner_deg``
    (``corner``: the acute corner's angle); ``radius_m`` (``bow``: the front's
    radius); ``rise_m`` (``slope``: ground rise from the front to the back facade);
    ``step_m`` (``sawtooth``: length of each small facade).
    """

    model: HeldoutModel = "hip"
    width_m: float = 13.0
    depth_m: float = 9.5
    floors: int = 2
    floor_height_m: float = 3.0
    roof_m: float = 3.2
    window_width_m: float = 1.2
    window_height_m: float = 1.4
    reveal_m: float = 0.08
    setback_m: float = 2.0
    recess_m: float = 1.6
    corner_deg: float = 60.0
    radius_m: float = 14.0
    rise_m: float = 1.6
    step_m: float = 3.0

    def __post_init__(self) -> None:
        if self.model not in HELDOUT_MODELS:
            raise ValueError(
                f"unknown held-out design {self.model!r}; choose one of {', '.join(HELDOUT_MODELS)}"
            )
        if self.floors < 1:
            raise ValueError(f"floors must be >= 1, got {self.floors}; a building needs a storey")
        for name in ("width_m", "depth_m", "floor_height_m", "roof_m", "window_width_m",
                     "window_height_m", "reveal_m", "setback_m", "recess_m", "radius_m",
                     "rise_m", "step_m"):
            if getattr(self, name) <= 0:
                raise ValueError(f"{name} must be > 0, got {getattr(self, name)}")
        if not 30.0 <= self.corner_deg <= 85.0:
            raise ValueError(f"corner_deg must be in [30, 85] degrees, got {self.corner_deg}")


def default_heldout_params(model: HeldoutModel) -> HeldoutParams:
    """The nominal parameters of a design (the seed jitters around these)."""
    nominal = {
        "hip": HeldoutParams("hip"),
        "mansard": HeldoutParams("mansard", 15.0, 10.0, 4, 3.0, 3.0, 1.1, 1.5),
        "setback": HeldoutParams("setback", 16.0, 12.0, 9, 3.1, 1.1, 1.3, 1.6, setback_m=2.0),
        "loggia": HeldoutParams("loggia", 15.0, 11.0, 5, 3.0, 1.0, 1.2, 1.4, recess_m=1.6),
        "corner": HeldoutParams("corner", 18.0, 10.0, 5, 3.0, 1.0, 1.2, 1.4, corner_deg=60.0),
        "bow": HeldoutParams("bow", 16.0, 10.0, 4, 3.1, 1.0, 1.0, 1.5, radius_m=13.0),
        "slope": HeldoutParams("slope", 13.0, 11.0, 3, 3.0, 1.0, 1.2, 1.4, rise_m=1.6),
        "sawtooth": HeldoutParams("sawtooth", 16.0, 14.0, 5, 3.0, 1.0, 1.0, 1.4, step_m=2.6),
    }
    if model not in nominal:
        raise ValueError(
            f"unknown held-out design {model!r}; choose one of {', '.join(HELDOUT_MODELS)}")
    return nominal[model]
