"""Held-out design ``loggia``: a block with loggias above a covered passage.

A ``width_m`` x ``depth_m`` block of ``floors`` storeys under a parapet ``roof_m``
high. The south facade's window bays are :data:`dataset.families.heldout_openings.BAY_M`
wide; its two middle bays hold, on the ground floor, a covered passage (the
ground floor recessed ``recess_m``: shop windows and a door at its back) and, on
every floor above, a loggia (a balcony recessed ``recess_m`` into the block, a
glazed balcony door at its back, a railing just behind the facade plane).

Truth decisions (``docs/buildings.md``): a recess's back wall belongs to the facade
it is recessed from (same id and normal; the facade's width stays the front's
length and its gross area the front's outline), because an elevation drawing shows
it there. A recess's sides are class wall and its floor and ceiling class other,
all facade 0 (like an opening's reveal: never facade area). The loggia's hole in
the front wall is a contact (:class:`dataset.families.facade_geometry.WallSpec`):
the recess closes it. The passage is a notch in the front wall's outline and in
the footprint (the building's section just above the ground), so the footprint is
the ground floor's outline, not the floors' above.
"""

from __future__ import annotations

import numpy as np
from shapely.geometry import Polygon

from dataset.families.building_assembly import BuildingLayout
from dataset.families.facade_geometry import MIN_GAP_M, Opening, WallFrame, WallSpec
from dataset.families.heldout_openings import (
    MARGIN_M,
    columns_for,
    rectangle_footprint,
    wall_openings,
)
from dataset.families.heldout_params import HeldoutParams
from dataset.families.polygon_mesh import PlanarFace, extruded_faces
from dataset.families.prism import edge_frames, ground_face, parapet_roof_faces
from envelope.classes import SemanticClass

PARAPET_THICKNESS_M = 0.3
CEILING_BELOW_FLOOR_M = 0.35  # a recess's ceiling stays this far under the next floor
LOGGIA_FLOOR_M = 0.1  # a loggia's floor above its storey's floor level
LOGGIA_SIDE_M = 0.3  # wall kept between a loggia and its bay's edge
RAILING_HEIGHT_M = 1.0
RAILING_THICKNESS_M = 0.05
RAILING_SETBACK_M = 0.1  # the railing's front face behind the facade plane
RAILING_GAP_M = 0.01  # off the loggia's floor and sides: its own closed body
BALCONY_DOOR_HEIGHT_M = 2.1


def recess_faces(front: WallFrame, u0_m: float, u1_m: float, v0_m: float, v1_m: float,
                 depth_m: float, *, floor: bool) -> list[PlanarFace]:
    """Sides (class wall), ceiling and, with ``floor``, floor (class other) of a recess.

    The recess spans u0..u1 and v0..v1 of the wall ``front`` and reaches ``depth_m``
    behind it; all faces belong to no facade. Its back wall is a :class:`WallSpec` of
    :func:`back_frame`.
    """
    def ring(corners: list[tuple[float, float, float]]) -> np.ndarray:
        return front.points_m(np.array(corners))

    along, up = front.u_axis, np.array([0.0, 0.0, 1.0])
    r = -depth_m
    faces = [
        PlanarFace((ring([(u0_m, v0_m, 0), (u0_m, v0_m, r), (u0_m, v1_m, r), (u0_m, v1_m, 0)]),),
                   along, SemanticClass.WALL),
        PlanarFace((ring([(u1_m, v0_m, 0), (u1_m, v0_m, r), (u1_m, v1_m, r), (u1_m, v1_m, 0)]),),
                   -along, SemanticClass.WALL),
        PlanarFace((ring([(u0_m, v1_m, 0), (u1_m, v1_m, 0), (u1_m, v1_m, r), (u0_m, v1_m, r)]),),
                   -up, SemanticClass.OTHER),
    ]
    if floor:
        faces.append(PlanarFace(
            (ring([(u0_m, v0_m, 0), (u1_m, v0_m, 0), (u1_m, v0_m, r), (u0_m, v0_m, r)]),),
            up, SemanticClass.OTHER))
    return faces


def back_frame(front: WallFrame, u0_m: float, u1_m: float, depth_m: float) -> WallFrame:
    """The frame of a recess's back wall: u0..u1 of ``front``, ``depth_m`` behind it."""
    p = front.points_m(np.array([[u0_m, 0.0, -depth_m], [u1_m, 0.0, -depth_m]]))[:, :2]
    return WallFrame(tuple(p[0]), tuple(p[1]))


def _railing(front: WallFrame, u0_m: float, u1_m: float, floor_z_m: float) -> list[PlanarFace]:
    a, b = u0_m + RAILING_GAP_M, u1_m - RAILING_GAP_M
    w0, w1 = -RAILING_SETBACK_M - RAILING_THICKNESS_M, -RAILING_SETBACK_M
    xy = front.points_m(np.array([(a, 0, w0), (b, 0, w0), (b, 0, w1), (a, 0, w1)]))[:, :2]
    return extruded_faces(Polygon(xy), floor_z_m + RAILING_GAP_M, floor_z_m + RAILING_HEIGHT_M,
                          label=SemanticClass.OTHER)


def loggia_layout(params: HeldoutParams) -> BuildingLayout:
    """Walls (the south facade with its recesses), railings, parapet roof and the ground."""
    w, d, n, fh, r = (params.width_m, params.depth_m, params.floors, params.floor_height_m,
                      params.recess_m)
    if n < 2:
        raise ValueError(f"the loggia design needs floors >= 2 (loggias start on floor 1), got {n}")
    if r >= d / 2:
        raise ValueError(f"recess {r} m is too deep for a block {d} m deep")
    rect = rectangle_footprint(w, d)
    frames = edge_frames(rect)
    south = frames[0]
    cols = columns_for(w)
    if cols < 4:
        raise ValueError(f"the loggia design needs >= 4 window bays on its south facade, "
                         f"got {cols}")
    bay = (w - 2 * MARGIN_M) / cols
    pa, pb = MARGIN_M + bay * (cols // 2 - 1), MARGIN_M + bay * (cols // 2 + 1)
    passage_h = fh - CEILING_BELOW_FLOOR_M
    top = n * fh + params.roof_m
    outline = np.array([[0.0, 0.0], [pa, 0.0], [pa, passage_h], [pb, passage_h], [pb, 0.0],
                        [w, 0.0], [w, top], [0.0, top]])
    clear = (pa - MIN_GAP_M, pb + MIN_GAP_M)
    windows = [o for o in wall_openings(w, params)
               if o.u1_m < clear[0] or o.u0_m > clear[1] or o.v0_m > fh]
    loggias = [(pa + k * bay + LOGGIA_SIDE_M, pa + (k + 1) * bay - LOGGIA_SIDE_M)
               for k in range(2)]
    contacts = [(u0, f * fh + LOGGIA_FLOOR_M, u1, (f + 1) * fh - CEILING_BELOW_FLOOR_M)
                for f in range(1, n) for u0, u1 in loggias]
    windows = [o for o in windows if not any(
        o.u1_m > c[0] - MIN_GAP_M and o.u0_m < c[2] + MIN_GAP_M and o.v0_m >= fh
        for c in contacts)]
    walls = [WallSpec(south, 1, outline, tuple(windows), tuple(contacts))]
    passage = back_frame(south, pa, pb, r)
    walls.append(WallSpec(passage, 1, np.array([[0.0, 0.0], [pb - pa, 0.0], [pb - pa, passage_h],
                                                 [0.0, passage_h]]),
                          tuple(wall_openings(pb - pa, params, floors=1, door=True))))
    other = recess_faces(south, pa, pb, 0.0, passage_h, r, floor=False)
    for u0, v0, u1, v1 in contacts:
        length = u1 - u0
        door = Opening("window", length / 2 - params.window_width_m / 2, v0 + 0.1,
                       length / 2 + params.window_width_m / 2, v0 + 0.1 + BALCONY_DOOR_HEIGHT_M,
                       params.reveal_m)
        outline_uv = np.array([[0.0, v0], [length, v0], [length, v1], [0.0, v1]])
        walls.append(WallSpec(back_frame(south, u0, u1, r), 1, outline_uv, (door,)))
        other += recess_faces(south, u0, u1, v0, v1, r, floor=True)
        other += _railing(south, u0, u1, v0)
    for i, frame in enumerate(frames[1:], start=2):
        walls.append(WallSpec(frame, i, np.array([[0.0, 0.0], [frame.length_m, 0.0],
                                                   [frame.length_m, top], [0.0, top]]),
                              tuple(wall_openings(frame.length_m, params, door=i == 3))))
    notch = south.points_m(np.array([[pa, 0, 0], [pa, 0, -r], [pb, 0, -r], [pb, 0, 0]]))[:, :2]
    footprint = np.concatenate([rect[:1], notch, rect[1:]])
    roof = parapet_roof_faces(rect, n * fh, params.roof_m, PARAPET_THICKNESS_M)
    return BuildingLayout(
        footprint_xy=footprint, walls=walls, other_faces=[ground_face(footprint), *roof, *other],
        floors=n, height_m=top,
        extra={"roof": {"kind": "parapet", "parapet_height_m": params.roof_m,
                        "parapet_thickness_m": PARAPET_THICKNESS_M},
               "recesses": {"depth_m": r, "passage_u_m": [pa, pb], "passage_height_m": passage_h,
                            "loggias": len(contacts)}},
    )
