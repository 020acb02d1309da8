"""Held-out design ``setback``: a tower of three tiers, each set back on every side.

The lowest tier stands on the ``width_m`` x ``depth_m`` rectangle; each tier above
is inset ``setback_m`` on every side and stands on the flat roof (a terrace,
class roof) of the one below. Of ``floors`` storeys the top tier holds
``floors // 4``, the middle one ``floors // 3`` and the lowest the rest; the top
tier's walls rise ``roof_m`` above its roof as a parapet. Every wall is its own
facade: tier t's edge i (south, east, north, west) is facade ``4 t + i + 1``, so a
tier's facades stand behind and above the ones below them. The door is on
facade 1.
"""

from __future__ import annotations

import numpy as np

from dataset.families.building_assembly import BuildingLayout
from dataset.families.facade_geometry import WallSpec
from dataset.families.heldout_openings import rectangle_footprint, wall_openings
from dataset.families.heldout_params import HeldoutParams
from dataset.families.polygon_mesh import PlanarFace
from dataset.families.prism import UP, edge_frames, ground_face, parapet_roof_faces
from envelope.classes import SemanticClass

PARAPET_THICKNESS_M = 0.3
TIERS = 3


def tier_floors(floors: int) -> tuple[int, int, int]:
    """Storeys of the lowest, middle and top tier."""
    top, middle = max(1, floors // 4), max(1, floors // 3)
    if floors - top - middle < 1:
        raise ValueError(f"a setback tower needs floors >= 3, got {floors}")
    return floors - top - middle, middle, top


def setback_layout(params: HeldoutParams) -> BuildingLayout:
    """Walls of the three tiers, their terraces, the parapet roof and the ground."""
    w, d, fh, s = params.width_m, params.depth_m, params.floor_height_m, params.setback_m
    if min(w, d) - 2 * (TIERS - 1) * s < 3.0:
        raise ValueError(f"setbacks of {s} m leave the top tier under 3 m wide on {w} x {d}")
    counts = tier_floors(params.floors)
    rings = [rectangle_footprint(w - 2 * t * s, d - 2 * t * s) for t in range(TIERS)]
    walls: list[WallSpec] = []
    terraces: list[PlanarFace] = []
    first = 0
    for t, (ring, count) in enumerate(zip(rings, counts)):
        z0, z1 = first * fh, (first + count) * fh
        top = z1 + (params.roof_m if t == TIERS - 1 else 0.0)
        for i, frame in enumerate(edge_frames(ring)):
            length = frame.length_m
            outline = np.array([[0.0, z0], [length, z0], [length, top], [0.0, top]])
            openings = wall_openings(length, params, floors=first + count, first_floor=first,
                                     door=t == 0 and i == 0)
            walls.append(WallSpec(frame, 4 * t + i + 1, outline, tuple(openings)))
        if t < TIERS - 1:
            outer = np.column_stack([ring, np.full(4, z1)])
            inner = np.column_stack([rings[t + 1], np.full(4, z1)])
            terraces.append(PlanarFace((outer, inner), UP, SemanticClass.ROOF))
        first += count
    roof_z = params.floors * fh
    roof = parapet_roof_faces(rings[-1], roof_z, params.roof_m, PARAPET_THICKNESS_M)
    return BuildingLayout(
        footprint_xy=rings[0], walls=walls,
        other_faces=[ground_face(rings[0]), *terraces, *roof],
        floors=params.floors, height_m=roof_z + params.roof_m,
        extra={"roof": {"kind": "setback", "tier_floors": list(counts), "setback_m": s,
                        "parapet_height_m": params.roof_m,
                        "parapet_thickness_m": PARAPET_THICKNESS_M}},
    )
