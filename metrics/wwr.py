"""The one definition of the window-to-wall ratio (DESIGN.md).

WWR = window area / gross facade area, gross facade = wall + window + door.
This module imports nothing from the project, so that the dataset's ground
truth and every method can use it without reversing the data flow.
"""

from __future__ import annotations


def gross_facade_area_m2(wall_area_m2: float, window_area_m2: float, door_area_m2: float) -> float:
    """Gross facade area in m²: opaque wall + window + door."""
    for name, value in (("wall", wall_area_m2), ("window", window_area_m2), ("door", door_area_m2)):
        if value < 0:
            raise ValueError(f"{name} area must be >= 0 m², got {value}")
    return float(wall_area_m2) + float(window_area_m2) + float(door_area_m2)


def window_to_wall_ratio(window_area_m2: float, gross_facade_area_m2: float) -> float:
    """WWR = window area / gross facade area (both m²), in [0, 1].

    Raises
    ------
    ValueError
        If the facade area is not positive or the window area exceeds it.
    """
    if gross_facade_area_m2 <= 0:
        raise ValueError(f"gross facade area must be > 0 m², got {gross_facade_area_m2}")
    if window_area_m2 < 0:
        raise ValueError(f"window area must be >= 0 m², got {window_area_m2}")
    ratio = float(window_area_m2) / float(gross_facade_area_m2)
    if ratio > 1.0 + 1e-9:
        raise ValueError(
            f"window area {window_area_m2} m² exceeds gross facade area {gross_facade_area_m2} m²"
        )
    return min(ratio, 1.0)
