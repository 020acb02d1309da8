"""The realistic family's parameters: one record for all four models, and their nominal values.

The models (:mod:`dataset.families.realistic_house`, ``_rounded``, ``_balcony``) read
:class:`RealisticParams`; :func:`dataset.families.realistic.realistic_layout` checks
that openings, balconies and roof fit.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

RealisticModel = Literal["house", "rounded", "balcony_a", "balcony_b"]
REALISTIC_MODELS: tuple[str, ...] = ("house", "rounded", "balcony_a", "balcony_b")


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
