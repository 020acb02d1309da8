"""The one definition of the window-to-wall ratio (docs/DESIGN.md), in the core every package
imports.

WWR = window area / gross facade area, gross facade = wall + window + door.
Areas in m² come in as one value, :class:`ClassAreas` (``.gross_m2``, ``.wwr``):
ground truth, importers and neural3d build one and read both figures from it.
:func:`wwr_from_areas` is the same ratio on arrays of class counts in any one
unit (the 2D methods' pixel counts); :attr:`ClassAreas.wwr` calls it, and
nothing else divides a window area by a facade area.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ClassAreas:
    """Window, opaque wall and door areas of one facade or one building, m² (each >= 0).

    Raises
    ------
    ValueError
        If an area is negative or not finite.
    """

    window_m2: float
    wall_m2: float
    door_m2: float

    def __post_init__(self) -> None:
        for name in ("window_m2", "wall_m2", "door_m2"):
            value = float(getattr(self, name))
            if not math.isfinite(value) or value < 0:
                raise ValueError(f"{name.removesuffix('_m2')} area must be finite and >= 0 m², "
                                 f"got {getattr(self, name)}")
            object.__setattr__(self, name, value)

    @property
    def gross_m2(self) -> float:
        """Gross facade area in m²: opaque wall + window + door."""
        return self.wall_m2 + self.window_m2 + self.door_m2

    @property
    def wwr(self) -> float | None:
        """window / gross in [0, 1]; None without facade (all three areas 0)."""
        return wwr_from_areas(self.window_m2, self.wall_m2, self.door_m2)


def wwr_from_areas(window_area, wall_area, door_area):
    """WWR = window / (wall + window + door) of class areas, in [0, 1].

    For areas in m² build a :class:`ClassAreas`; this form takes arrays and
    other units.

    Parameters
    ----------
    window_area, wall_area, door_area : float or (...) array_like
        Areas of the three facade classes in one unit (m², or pixels for a
        pixel-count ratio); arrays broadcast against each other.

    Returns
    -------
    float or None, or (...) float ndarray
        For scalar inputs the ratio, or ``None`` where there is no facade
        (all three areas 0). For array inputs an array with NaN there.

    Raises
    ------
    ValueError
        If an area is negative or not finite.
    """
    window, wall, door = np.broadcast_arrays(
        *(np.asarray(a, dtype=float) for a in (window_area, wall_area, door_area)))
    for name, value in (("window", window), ("wall", wall), ("door", door)):
        if not np.all(np.isfinite(value)) or np.any(value < 0):
            raise ValueError(f"{name} area must be finite and >= 0, got {value}")
    gross = wall + window + door
    ratio = np.divide(window, gross, out=np.full(gross.shape, np.nan), where=gross > 0)
    ratio = np.minimum(ratio, 1.0)  # float round-off of window + 0 + 0 never exceeds 1
    if ratio.ndim == 0:
        return None if np.isnan(ratio) else float(ratio)
    return ratio
