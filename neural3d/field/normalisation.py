"""World metres <-> the normalised frame the fields work in (applied once, on load).

``unit = (world_m - centre_m) / scale_m``: a translation and one isotropic scale,
so signed distances convert by ``* scale_m`` and directions are unchanged. The
scene box's longest half-side becomes 1, so the box lies inside [-1, 1]^3.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import torch
from torch import Tensor


@dataclass(frozen=True)
class Normalisation:
    """The world scene box and the similarity that maps it into [-1, 1]^3.

    ``box_min_m``, ``box_max_m``: (3,) world corners of the modelled box.
    """

    box_min_m: tuple[float, float, float]
    box_max_m: tuple[float, float, float]

    def __post_init__(self) -> None:
        lo, hi = np.asarray(self.box_min_m), np.asarray(self.box_max_m)
        if lo.shape != (3,) or hi.shape != (3,) or not np.all(hi > lo):
            raise ValueError(
                f"scene box needs 3 coordinates with max > min, got {self.box_min_m}, "
                f"{self.box_max_m}"
            )

    @staticmethod
    def from_box(box_min_m: np.ndarray, box_max_m: np.ndarray) -> Normalisation:
        return Normalisation(
            tuple(float(v) for v in box_min_m), tuple(float(v) for v in box_max_m)
        )

    @property
    def centre_m(self) -> np.ndarray:
        """(3,) world centre of the box."""
        return (np.asarray(self.box_min_m) + np.asarray(self.box_max_m)) / 2

    @property
    def scale_m(self) -> float:
        """Metres per normalised unit: half the box's longest side."""
        return float(np.max(np.asarray(self.box_max_m) - np.asarray(self.box_min_m)) / 2)

    @property
    def box_min_unit(self) -> np.ndarray:
        """(3,) box corner in the normalised frame."""
        return (np.asarray(self.box_min_m) - self.centre_m) / self.scale_m

    @property
    def box_max_unit(self) -> np.ndarray:
        """(3,) box corner in the normalised frame."""
        return (np.asarray(self.box_max_m) - self.centre_m) / self.scale_m

    def unit_from_world(self, points_world_m: Tensor) -> Tensor:
        """"(..., 3)" world points (m) -> "(..., 3)" normalised points."""
        c = torch.as_tensor(self.centre_m, dtype=points_world_m.dtype,
                            device=points_world_m.device)
        return (points_world_m - c) / self.scale_m

    def world_from_unit(self, points_unit: Tensor) -> Tensor:
        """"(..., 3)" normalised points -> "(..., 3)" world points (m)."""
        c = torch.as_tensor(self.centre_m, dtype=points_unit.dtype, device=points_unit.device)
        return points_unit * self.scale_m + c

    def to_json_dict(self) -> dict[str, Any]:
        return {
            "box_min_m": list(self.box_min_m), "box_max_m": list(self.box_max_m),
            "centre_m": self.centre_m.tolist(), "scale_m": self.scale_m,
        }

    @staticmethod
    def from_json_dict(d: dict[str, Any]) -> Normalisation:
        return Normalisation.from_box(np.asarray(d["box_min_m"]), np.asarray(d["box_max_m"]))
