"""Realistic model ``house``: a residential house with a gable roof.

Rectangular footprint ``width_m`` (x, along the ridge) by ``depth_m`` (y),
``floors`` storeys below the eaves and a gable roof rising ``roof_m`` to the
ridge, covered by a roof slab that overhangs eaves and gables (its own closed
body, floating 1 cm above the roof planes). Facades: 1 south (front door, large
ground-floor windows), 2 east gable, 3 north (back door, small ground-floor
windows), 4 west gable; each gable has a small attic window in its triangle. A
chimney (class other, its own closed body) rises through the north slope; it
starts inside the house, so it needs no hole in the roof.
"""

from __future__ import annotations

import numpy as np
from shapely.geometry import box

from dataset.families.building_assembly import BuildingLayout
from dataset.families.facade_geometry import Opening, drop_near, window_grid
from dataset.families.polygon_mesh import extruded_faces
from dataset.families.prism import (
    gable_roof_faces,
    gable_roof_shell_faces,
    gable_walls,
    ground_face,
)
from dataset.families.realistic_params import RealisticParams
from envelope.classes import SemanticClass

DOOR_WIDTH_M = 1.1
DOOR_HEIGHT_M = 2.2
DOOR_THRESHOLD_M = 0.15
CHIMNEY_SIZE_M = 0.6
CHIMNEY_ABOVE_RIDGE_M = 0.6
EAVES_OVERHANG_M = 0.4
ROOF_SHELL_THICKNESS_M = 0.2
ROOF_SHELL_GAP_M = 0.01


def _door(centre_u: float, depth_m: float) -> Opening:
    return Opening(
        "door", centre_u - DOOR_WIDTH_M / 2, DOOR_THRESHOLD_M, centre_u + DOOR_WIDTH_M / 2,
        DOOR_THRESHOLD_M + DOOR_HEIGHT_M, depth_m,
    )


def house_layout(params: RealisticParams) -> BuildingLayout:
    """Walls, gable roof, ground and chimney of the house."""
    w, d, n, fh = params.width_m, params.depth_m, params.floors, params.floor_height_m
    ww, wh, reveal = params.window_width_m, params.window_height_m, params.reveal_m
    eave, ridge = n * fh, n * fh + params.roof_m
    footprint = np.array([[-w / 2, -d / 2], [w / 2, -d / 2], [w / 2, d / 2], [-w / 2, d / 2]])
    sill = 0.9

    def grid(length: float, cols: int, width: float, height: float, sill_m: float,
             first: int, floors: int) -> list[Opening]:
        return window_grid(
            length, floors, fh, columns=cols, window_width_m=width, window_height_m=height,
            sill_height_m=sill_m, margin_m=0.8, depth_m=reveal, first_floor=first,
        )

    front_door = _door(w / 2, reveal + 0.02)
    back_door = _door(w * 0.3, reveal + 0.02)
    south = [front_door, *drop_near(grid(w, 4, ww * 1.4, wh * 1.15, 0.6, 0, 1), [front_door])]
    south += grid(w, 4, ww, wh, sill, 1, n)
    north = [back_door, *drop_near(grid(w, 5, ww * 0.6, wh * 0.7, 1.3, 0, 1), [back_door])]
    north += grid(w, 4, ww, wh, sill, 1, n)
    gables = []
    for _ in range(2):
        half = ww * 0.35
        attic = Opening("window", d / 2 - half, eave + 0.5, d / 2 + half, eave + 0.5 + wh * 0.8,
                        reveal)
        gables.append([*grid(d, 2, ww, wh, sill, 0, n), attic])
    walls = gable_walls(footprint, eave, ridge, [1, 2, 3, 4], [south, gables[0], north, gables[1]])
    shell, top = gable_roof_shell_faces(walls, EAVES_OVERHANG_M, ROOF_SHELL_THICKNESS_M,
                                        ROOF_SHELL_GAP_M)
    cx, cy, half = w / 4, d / 4, CHIMNEY_SIZE_M / 2
    chimney = extruded_faces(
        box(cx - half, cy - half, cx + half, cy + half), eave - 0.5,
        ridge + CHIMNEY_ABOVE_RIDGE_M, label=SemanticClass.OTHER,
    )
    return BuildingLayout(
        footprint_xy=footprint,
        walls=walls,
        other_faces=[ground_face(footprint), *gable_roof_faces(walls), *shell, *chimney],
        floors=n,
        height_m=top,
        extra={
            "roof": {"kind": "gable", "eave_height_m": eave, "ridge_height_m": ridge,
                     "overhang_m": EAVES_OVERHANG_M, "roof_top_m": top},
            "chimney_top_m": ridge + CHIMNEY_ABOVE_RIDGE_M,
        },
    )
