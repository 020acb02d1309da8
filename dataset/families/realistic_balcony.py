"""Realistic models ``balcony_a`` and ``balcony_b``: blocks whose balconies hide the facade.

Rectangular footprint ``width_m`` (x) by ``depth_m`` (y); facades 1 south
(door), 2 east, 3 north, 4 west; flat roof with a parapet ``roof_m`` high. From
the first floor up, the long facades (1 and 3) carry balconies in front of
storey-high glazed balcony doors (class window):

- ``balcony_a``: one balcony per bay (every bay on facade 1, every other bay on facade 3);
- ``balcony_b``: one continuous balcony per floor along each long facade.

A balcony is a slab (``balcony_depth_m`` deep, :data:`SLAB_THICKNESS_M` thick,
its top at floor level) whose contact rectangle is a hole in the wall, so wall
and slab form one closed solid, and a U-shaped railing that floats
:data:`RAILING_GAP_M` above the slab and off the wall as its own closed body.
Both are class other, facade 0. The contact rectangle is not facade area: the
truth's wall area excludes it (``extra["balcony_contact_area_m2"]``).
"""

from __future__ import annotations

import numpy as np
from shapely.geometry import Polygon

from dataset.families.building_assembly import BuildingLayout
from dataset.families.facade_geometry import Opening, WallFrame
from dataset.families.polygon_mesh import PlanarFace, extruded_faces
from dataset.families.prism import edge_frames, ground_face, parapet_roof_faces, prism_walls
from dataset.families.realistic_params import RealisticParams
from envelope.classes import SemanticClass

SLAB_THICKNESS_M = 0.2
RAILING_GAP_M = 0.01
RAILING_THICKNESS_M = 0.05
RAILING_INSET_M = 0.02
BALCONY_DOOR_HEIGHT_M = 2.1
BALCONY_DOOR_SILL_M = 0.1
PARAPET_THICKNESS_M = 0.3
BAY_M = 3.4
MARGIN_M = 0.8


def balcony_faces(
    frame: WallFrame, u0_m: float, u1_m: float, slab_top_m: float, depth_m: float,
    railing_height_m: float,
) -> list[PlanarFace]:
    """Slab (without its wall-side face) and railing of one balcony on the wall ``frame``.

    The slab spans u0..u1 along the wall and ``depth_m`` out; the wall needs the
    contact hole (u0, slab_top - thickness, u1, slab_top).
    """
    v0, v1 = slab_top_m - SLAB_THICKNESS_M, slab_top_m

    def pts(u: float, v: float, w: float) -> np.ndarray:
        return frame.points_m(np.array([[u, v, w]]))[0]

    def quad(corners: list[tuple[float, float, float]], normal: np.ndarray) -> PlanarFace:
        ring = np.stack([pts(*c) for c in corners])
        return PlanarFace((ring,), normal, SemanticClass.OTHER)

    up, out, along = np.array([0.0, 0.0, 1.0]), frame.normal, frame.u_axis
    slab = [
        quad([(u0_m, v1, 0), (u1_m, v1, 0), (u1_m, v1, depth_m), (u0_m, v1, depth_m)], up),
        quad([(u0_m, v0, 0), (u1_m, v0, 0), (u1_m, v0, depth_m), (u0_m, v0, depth_m)], -up),
        quad([(u0_m, v0, depth_m), (u1_m, v0, depth_m), (u1_m, v1, depth_m),
              (u0_m, v1, depth_m)], out),
        quad([(u0_m, v0, 0), (u0_m, v0, depth_m), (u0_m, v1, depth_m), (u0_m, v1, 0)], -along),
        quad([(u1_m, v0, 0), (u1_m, v0, depth_m), (u1_m, v1, depth_m), (u1_m, v1, 0)], along),
    ]
    a, b = u0_m + RAILING_INSET_M, u1_m - RAILING_INSET_M
    e, f, t = RAILING_GAP_M, depth_m - RAILING_INSET_M, RAILING_THICKNESS_M
    u_shape_uw = [(a, e), (a, f), (b, f), (b, e), (b - t, e), (b - t, f - t), (a + t, f - t),
                  (a + t, e)]
    ring = frame.points_m(np.array([(u, 0.0, w) for u, w in u_shape_uw]))[:, :2]
    railing = extruded_faces(
        Polygon(ring), slab_top_m + RAILING_GAP_M, slab_top_m + railing_height_m,
        label=SemanticClass.OTHER,
    )
    return slab + railing


def balcony_layout(params: RealisticParams, *, continuous: bool) -> BuildingLayout:
    """Walls with balcony doors and contact holes, balconies, parapet roof and ground."""
    w, d, n, fh = params.width_m, params.depth_m, params.floors, params.floor_height_m
    ww, wh, reveal, depth = (params.window_width_m, params.window_height_m, params.reveal_m,
                             params.balcony_depth_m)
    if n < 2:
        raise ValueError(f"balcony models need floors >= 2 (balconies start on floor 1), got {n}")
    footprint = np.array([[-w / 2, -d / 2], [w / 2, -d / 2], [w / 2, d / 2], [-w / 2, d / 2]])
    frames = edge_frames(footprint)
    sill = 0.9
    railing_h = 1.1 if continuous else 1.0
    openings: list[list[Opening]] = []
    contacts: list[list[tuple[float, float, float, float]]] = []
    attached: list[PlanarFace] = []
    contact_area = {}
    for i, frame in enumerate(frames):
        length = frame.length_m
        cols = max(1, round((length - 2 * MARGIN_M) / BAY_M))
        bay = (length - 2 * MARGIN_M) / cols
        ops: list[Opening] = []
        cts: list[tuple[float, float, float, float]] = []
        for k in range(n):
            z = k * fh
            for c in range(cols):
                centre = MARGIN_M + (c + 0.5) * bay
                on_balcony = i in (0, 2) and k >= 1 and (continuous or i == 0 or c % 2 == 0)
                if on_balcony:
                    ops.append(Opening("window", centre - ww / 2, z + BALCONY_DOOR_SILL_M,
                                       centre + ww / 2, z + BALCONY_DOOR_SILL_M
                                       + BALCONY_DOOR_HEIGHT_M, reveal))
                    if not continuous:
                        half = min(bay - 1.0, 2.4) / 2  # visibly separate balconies
                        cts.append((centre - half, z - SLAB_THICKNESS_M, centre + half, z))
                elif not (i == 0 and k == 0 and c == cols // 2):  # the door's bay
                    ops.append(Opening("window", centre - ww / 2, z + sill, centre + ww / 2,
                                       z + sill + wh, reveal))
            if continuous and i in (0, 2) and k >= 1:
                cts.append((0.4, z - SLAB_THICKNESS_M, length - 0.4, z))
        if i == 0:
            centre = MARGIN_M + (cols // 2 + 0.5) * bay
            ops.append(Opening("door", centre - 0.8, 0.15, centre + 0.8, 2.45, reveal + 0.02))
        for u0, _, u1, v1 in cts:
            attached += balcony_faces(frame, u0, u1, v1, depth, railing_h)
        contact_area[str(i + 1)] = float(sum((c[2] - c[0]) * (c[3] - c[1]) for c in cts))
        openings.append(ops)
        contacts.append(cts)
    top = n * fh
    walls = prism_walls(footprint, top + params.roof_m, [1, 2, 3, 4], openings, contacts)
    roof = parapet_roof_faces(footprint, top, params.roof_m, PARAPET_THICKNESS_M)
    return BuildingLayout(
        footprint_xy=footprint,
        walls=walls,
        other_faces=[ground_face(footprint), *roof, *attached],
        floors=n,
        height_m=top + params.roof_m,
        extra={
            "roof": {"kind": "parapet", "parapet_height_m": params.roof_m,
                     "parapet_thickness_m": PARAPET_THICKNESS_M},
            "balconies": "continuous" if continuous else "per_bay",
            "balcony_contact_area_m2": contact_area,
        },
    )
