"""Realistic model ``rounded``: a block whose east end is a half-round curved facade.

The footprint is a ``width_m`` (x) by ``depth_m`` (y) stadium half: a rectangle
whose east end is a half circle of radius ``depth_m / 2``, faceted into planar
segments of about :data:`FACET_TARGET_M` chord. Facades: 1 south (door), 2 the
curved wall (all facets, ``curved=True``, width = summed chord length), 3 north,
4 west. Every other facet holds one window per floor, flat in its facet, so the
windows stay planar rectangles. Flat roof with a parapet ``roof_m`` high.
"""

from __future__ import annotations

import numpy as np

from dataset.families.building_assembly import BuildingLayout
from dataset.families.facade_geometry import Opening, drop_near, window_grid
from dataset.families.prism import ground_face, parapet_roof_faces, prism_walls
from dataset.families.realistic_params import RealisticParams

FACET_TARGET_M = 1.8
PARAPET_THICKNESS_M = 0.3
STRAIGHT_BAY_M = 3.6
CURVED_FACADE_ID = 2
MIN_STRAIGHT_M = 2.0


def rounded_footprint(width_m: float, depth_m: float) -> tuple[np.ndarray, int]:
    """(n, 2) counter-clockwise footprint and its number of arc facets.

    The arc's end points are written exactly (no trigonometry), so the straight
    walls meet the first and last facet in shared vertices.
    """
    r = depth_m / 2
    xc = width_m / 2 - r
    if xc - (-width_m / 2) < MIN_STRAIGHT_M:
        raise ValueError(
            f"rounded model needs width >= depth / 2 + {MIN_STRAIGHT_M} m (a straight part), "
            f"got {width_m} x {depth_m}"
        )
    facets = max(6, round(np.pi * r / FACET_TARGET_M))
    angles = -np.pi / 2 + np.pi * np.arange(1, facets) / facets
    arc = np.column_stack([xc + r * np.cos(angles), r * np.sin(angles)])
    fp = np.concatenate([[[-width_m / 2, -r], [xc, -r]], arc, [[xc, r], [-width_m / 2, r]]])
    return fp, facets


def rounded_layout(params: RealisticParams) -> BuildingLayout:
    """Walls (one curved facade of many facets), parapet roof and ground of the model."""
    w, d, n, fh = params.width_m, params.depth_m, params.floors, params.floor_height_m
    ww, wh, reveal = params.window_width_m, params.window_height_m, params.reveal_m
    footprint, facets = rounded_footprint(w, d)
    lengths = np.linalg.norm(np.roll(footprint, -1, axis=0) - footprint, axis=1)
    straight_sill = 0.9

    def grid(length: float, width: float, sill: float):
        cols = max(1, round((length - 1.6) / STRAIGHT_BAY_M))
        return window_grid(
            length, n, fh, columns=cols, window_width_m=width, window_height_m=wh,
            sill_height_m=sill, margin_m=0.8, depth_m=reveal,
        )

    door_u = lengths[0] / 2
    door = Opening("door", door_u - 0.8, 0.15, door_u + 0.8, 2.45, reveal + 0.02)
    openings = [[door, *drop_near(grid(lengths[0], ww, straight_sill), [door])]]
    for k in range(facets):
        chord = float(lengths[1 + k])
        if k % 2 == 0:
            openings.append(
                window_grid(chord, n, fh, columns=1, window_width_m=min(ww, chord - 0.5),
                            window_height_m=wh, sill_height_m=straight_sill, margin_m=0.0,
                            depth_m=reveal)
            )
        else:
            openings.append([])
    openings.append(grid(lengths[facets + 1], ww, straight_sill))
    openings.append(grid(lengths[facets + 2], ww, straight_sill))
    facade_ids = [1] + [CURVED_FACADE_ID] * facets + [3, 4]
    top = n * fh
    walls = prism_walls(footprint, top + params.roof_m, facade_ids, openings)
    roof = parapet_roof_faces(footprint, top, params.roof_m, PARAPET_THICKNESS_M)
    return BuildingLayout(
        footprint_xy=footprint,
        walls=walls,
        other_faces=[ground_face(footprint), *roof],
        floors=n,
        height_m=top + params.roof_m,
        curved_facade_ids=frozenset({CURVED_FACADE_ID}),
        extra={
            "roof": {"kind": "parapet", "parapet_height_m": params.roof_m,
                     "parapet_thickness_m": PARAPET_THICKNESS_M},
            "curved_facade": {
                "id": CURVED_FACADE_ID, "centre_xy_m": [w / 2 - d / 2, 0.0], "radius_m": d / 2,
                "facets": facets, "arc_deg": 180.0,
            },
        },
    )
