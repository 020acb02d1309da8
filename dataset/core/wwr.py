"""The one definition of the window-to-wall ratio (DESIGN.md), in the core every package imports.

WWR = window area / gross facade area, gross facade = wall + window + door.
Ground truth, 2D-S and 2D-SS (pixel counts are areas in pixel units), neural3d
and the metrics all compute it through :func:`wwr_from_areas`; nothing else
divides a window area by a facade area.
"""

from __future__ import annotations

import numpy as np


def gross_facade_area_m2(wall_area_m2: float, window_area_m2: float, door_area_m2: float) -> float:
    """Gross facade area in m²: opaque wall + window + door.

    Raises
    ------
    ValueError
        If an area is negative.
    """
    for name, value in (("wall", wall_area_m2), ("window", window_area_m2), ("door", door_area_m2)):
        if value < 0:
            raise ValueError(f"{name} area must be >= 0 m², got {value}")
    return float(wall_area_m2) + float(window_area_m2) + float(door_area_m2)


def wwr_from_areas(window_area, wall_area, door_area):
    """WWR = window / (wall + window + door) of class areas, in [0, 1].

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
