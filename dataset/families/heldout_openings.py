"""Windows and doors of the held-out designs: a window grid per wall, a door where asked.

Every held-out design places its typical windows the same way: ``columns`` windows
per floor in equal bays (:func:`dataset.families.facade_geometry.window_grid`), the
column count following the wall's length (one per :data:`BAY_M`), optionally a
centred ground-floor door that clears the windows it would touch.
"""

from __future__ import annotations

import numpy as np

from dataset.families.facade_geometry import Opening, drop_near, window_grid
from dataset.families.heldout_params import HeldoutParams

BAY_M = 3.2
MARGIN_M = 0.6
SILL_M = 0.9
DOOR_WIDTH_M = 1.2
DOOR_HEIGHT_M = 2.2
DOOR_THRESHOLD_M = 0.12


def columns_for(length_m: float) -> int:
    """Window columns of a wall ``length_m`` long: one per :data:`BAY_M`, at least one."""
    return max(1, round((length_m - 2 * MARGIN_M) / BAY_M))


def wall_openings(
    length_m: float, params: HeldoutParams, *, floors: int | None = None, first_floor: int = 0,
    base_m: float = 0.0, door: bool = False, columns: int | None = None,
) -> list[Opening]:
    """Window grid (and a centred door) of a wall ``length_m`` long.

    Floors ``first_floor .. floors - 1`` (default: all of ``params.floors``) get windows;
    every opening is raised by ``base_m`` (the height of the wall's floor 0 above z = 0,
    e.g. on sloped ground). ``door``: a centred door on floor ``first_floor``.
    """
    floors = params.floors if floors is None else floors
    grid = window_grid(
        length_m, floors, params.floor_height_m, columns=columns or columns_for(length_m),
        window_width_m=params.window_width_m, window_height_m=params.window_height_m,
        sill_height_m=SILL_M, margin_m=MARGIN_M, depth_m=params.reveal_m,
        first_floor=first_floor,
    )
    if door:
        v0 = first_floor * params.floor_height_m + DOOR_THRESHOLD_M
        half = DOOR_WIDTH_M / 2
        front = Opening("door", length_m / 2 - half, v0, length_m / 2 + half, v0 + DOOR_HEIGHT_M,
                        params.reveal_m + 0.02)
        grid = [front, *drop_near(grid, [front])]
    return [raised(o, base_m) for o in grid] if base_m else grid


def raised(opening: Opening, dz_m: float) -> Opening:
    """``opening`` moved up by ``dz_m``."""
    return Opening(opening.kind, opening.u0_m, opening.v0_m + dz_m, opening.u1_m,
                   opening.v1_m + dz_m, opening.depth_m)


def rectangle_footprint(width_m: float, depth_m: float) -> np.ndarray:
    """(4, 2) counter-clockwise rectangle centred on the origin; edge 0 is the south one."""
    w, d = width_m / 2, depth_m / 2
    return np.array([[-w, -d], [w, -d], [w, d], [-w, d]])
