"""Held-out design ``slope``: a block on ground that rises ``rise_m`` from its front to its back.

How sloped ground is represented (``docs/buildings.md``): the world's ground
convention holds where the building meets the ground lowest: z = 0 is the ground
along the south (front) facade, and the terrain is the plane
``z = rise_m * (y + depth_m / 2) / depth_m`` under the building, reaching
``rise_m`` along the north (back) facade. The terrain itself is not geometry (as
flat ground is not: the renderer's ground is the plane z = 0 and its environment
map), so a camera low behind the building sees under its back edge. The walls
start on the terrain line: the south facade is a full rectangle with a plinth
``rise_m`` high (basement windows), the east and west facades have a sloping
bottom edge and the north facade starts at ``rise_m``; the truth counts only
facade above the terrain. The building's underside is the terrain plane under it
(class other, facade 0, like the ground face of a building on flat ground). The
footprint is the plan outline, i.e. the building's section just above the terrain
(on flat ground that is the section just above z = 0). Floor 0 is at the back's
ground level ``rise_m``; the door is on the north facade.
"""

from __future__ import annotations

import numpy as np

from dataset.families.building_assembly import BuildingLayout
from dataset.families.facade_geometry import WallSpec, window_grid
from dataset.families.heldout_openings import (
    MARGIN_M,
    columns_for,
    rectangle_footprint,
    wall_openings,
)
from dataset.families.heldout_params import HeldoutParams
from dataset.families.polygon_mesh import PlanarFace
from dataset.families.prism import edge_frames, parapet_roof_faces
from envelope.classes import SemanticClass

PARAPET_THICKNESS_M = 0.3
BASEMENT_SILL_M = 0.3
BASEMENT_WINDOW_MAX_M = 0.8
MIN_BASEMENT_WINDOWS_RISE_M = 1.0  # a plinth lower than this gets no basement windows


def terrain_underside(footprint_xy: np.ndarray, depth_m: float, rise_m: float) -> PlanarFace:
    """The building's underside on the terrain plane (class other, normal down the slope)."""
    ring = np.column_stack([footprint_xy, rise_m * (footprint_xy[:, 1] / depth_m + 0.5)])
    normal = np.array([0.0, rise_m / depth_m, -1.0])
    return PlanarFace((ring,), normal / np.linalg.norm(normal), SemanticClass.OTHER)


def slope_layout(params: HeldoutParams) -> BuildingLayout:
    """Walls on the terrain line, parapet roof and the underside on the terrain."""
    w, d, n, fh, rise = (params.width_m, params.depth_m, params.floors, params.floor_height_m,
                         params.rise_m)
    if rise > fh:
        raise ValueError(f"ground rising {rise} m under the building is more than a storey "
                         f"({fh} m); use a smaller rise_m")
    footprint = rectangle_footprint(w, d)
    top = rise + n * fh + params.roof_m
    bottoms = (((0.0, 0.0), (w, 0.0)), ((0.0, 0.0), (d, rise)),  # (u, v) of each wall's
               ((0.0, rise), (w, rise)), ((0.0, rise), (d, 0.0)))  # two bottom corners
    walls = []
    for i, (frame, (a, b)) in enumerate(zip(edge_frames(footprint), bottoms)):
        length = frame.length_m
        outline = np.array([a, b, (length, top), (0.0, top)])
        openings = wall_openings(length, params, base_m=rise, door=i == 2)
        if i == 0 and rise >= MIN_BASEMENT_WINDOWS_RISE_M:
            openings += window_grid(
                length, 1, rise, columns=columns_for(length),
                window_width_m=params.window_width_m, sill_height_m=BASEMENT_SILL_M,
                window_height_m=min(BASEMENT_WINDOW_MAX_M, rise - BASEMENT_SILL_M - 0.3),
                margin_m=MARGIN_M, depth_m=params.reveal_m)
        walls.append(WallSpec(frame, i + 1, outline, tuple(openings)))
    roof_z = rise + n * fh
    roof = parapet_roof_faces(footprint, roof_z, params.roof_m, PARAPET_THICKNESS_M)
    return BuildingLayout(
        footprint_xy=footprint, walls=walls,
        other_faces=[terrain_underside(footprint, d, rise), *roof],
        floors=n, height_m=top,
        extra={"roof": {"kind": "parapet", "parapet_height_m": params.roof_m,
                        "parapet_thickness_m": PARAPET_THICKNESS_M},
               "terrain": {"kind": "plane", "rise_m": rise, "uphill_xy": [0.0, 1.0],
                           "z_at_south_facade_m": 0.0, "z_at_north_facade_m": rise}},
    )
