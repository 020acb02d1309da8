"""Held-out designs ``hip`` and ``mansard``: rectangular blocks under roofs of other shapes.

- ``hip``: ``floors`` storeys under a hip roof whose four planes share one pitch
  and rise ``roof_m`` to a ridge along x (``width_m`` > ``depth_m``); every facade
  is a rectangle up to the eaves (no gables). A roof slab (class roof, its own
  closed body) floats :data:`SHELL_GAP_M` above the roof planes and overhangs every
  wall by :data:`HIP_OVERHANG_M`, as the house's gable slab does, so it hides a
  strip under the eaves from a camera in front.
- ``mansard``: ``floors`` storeys under a mansard: four steep slopes
  (:data:`MANSARD_PITCH_DEG`) rising ``roof_m`` from the eaves to a flat top.

Facades 1 south (door), 2 east, 3 north, 4 west; all roof faces are class roof.
"""

from __future__ import annotations

import numpy as np

from dataset.families.building_assembly import BuildingLayout
from dataset.families.heldout_openings import rectangle_footprint, wall_openings
from dataset.families.heldout_params import HeldoutParams
from dataset.families.polygon_mesh import PlanarFace, vertical_quad
from dataset.families.prism import UP, ground_face, prism_walls
from envelope.classes import SemanticClass

HIP_OVERHANG_M = 0.5
SHELL_THICKNESS_M = 0.2
SHELL_GAP_M = 0.01
MANSARD_PITCH_DEG = 70.0


def _face(ring: np.ndarray, *, down: bool = False) -> PlanarFace:
    """A roof face whose normal points up (``down``: down) by the ring's own winding."""
    normal = np.cross(ring[1] - ring[0], ring[2] - ring[1])
    normal = normal / np.linalg.norm(normal)
    if (normal[2] < 0) != down:
        normal = -normal
    return PlanarFace((ring,), normal, SemanticClass.ROOF)


def hip_surface(corners_xy: np.ndarray, eave_z_m: float, ridge_half_m: float,
                ridge_z_m: float, *, down: bool = False) -> list[PlanarFace]:
    """The four planes of a hip roof over the rectangle ``corners_xy`` (SW, SE, NE, NW).

    The ridge runs along x at y = the rectangle's middle, from -``ridge_half_m`` to
    +``ridge_half_m`` about its centre, at ``ridge_z_m``; the eaves are at ``eave_z_m``.
    """
    sw, se, ne, nw = (np.array([x, y, eave_z_m]) for x, y in corners_xy)
    cx, cy = corners_xy.mean(axis=0)
    west = np.array([cx - ridge_half_m, cy, ridge_z_m])
    east = np.array([cx + ridge_half_m, cy, ridge_z_m])
    rings = (np.stack([sw, se, east, west]), np.stack([se, ne, east]),
             np.stack([ne, nw, west, east]), np.stack([nw, sw, west]))
    return [_face(r, down=down) for r in rings]


def hip_layout(params: HeldoutParams) -> BuildingLayout:
    """Walls, hip roof, roof slab and ground of the ``hip`` design."""
    w, d, n, fh = params.width_m, params.depth_m, params.floors, params.floor_height_m
    if w < d + 1.0:
        raise ValueError(f"a hip roof with a ridge needs width >= depth + 1 m, got {w} x {d}")
    eave, rise = n * fh, params.roof_m
    footprint = rectangle_footprint(w, d)
    openings = [wall_openings(w, params, door=True), wall_openings(d, params),
                wall_openings(w, params), wall_openings(d, params)]
    walls = prism_walls(footprint, eave, [1, 2, 3, 4], openings)
    half = (w - d) / 2
    roof = hip_surface(footprint, eave, half, eave + rise)
    tan = rise / (d / 2)
    cos = 1.0 / np.hypot(1.0, tan)
    lift, thick = SHELL_GAP_M / cos, SHELL_THICKNESS_M / cos
    o = HIP_OVERHANG_M
    outer = rectangle_footprint(w + 2 * o, d + 2 * o)
    low = eave + lift - o * tan
    shell = hip_surface(outer, low, half, eave + rise + lift, down=True)
    shell += hip_surface(outer, low + thick, half, eave + rise + lift + thick)
    shell += [vertical_quad(p, q, low, low + thick, label=SemanticClass.ROOF)
              for p, q in zip(outer, np.roll(outer, -1, axis=0))]
    top = eave + rise + lift + thick
    return BuildingLayout(
        footprint_xy=footprint, walls=walls, other_faces=[ground_face(footprint), *roof, *shell],
        floors=n, height_m=top,
        extra={"roof": {"kind": "hip", "eave_height_m": eave, "ridge_height_m": eave + rise,
                        "ridge_length_m": w - d, "overhang_m": o, "roof_top_m": top}},
    )


def mansard_layout(params: HeldoutParams) -> BuildingLayout:
    """Walls, mansard roof and ground of the ``mansard`` design."""
    w, d, n, fh = params.width_m, params.depth_m, params.floors, params.floor_height_m
    eave, height = n * fh, params.roof_m
    inset = height / np.tan(np.radians(MANSARD_PITCH_DEG))
    if min(w, d) - 2 * inset < 2.0:
        raise ValueError(f"a mansard {height} m high leaves under 2 m of flat top on {w} x {d}")
    footprint = rectangle_footprint(w, d)
    openings = [wall_openings(w, params, door=True), wall_openings(d, params),
                wall_openings(w, params), wall_openings(d, params)]
    walls = prism_walls(footprint, eave, [1, 2, 3, 4], openings)
    inner = rectangle_footprint(w - 2 * inset, d - 2 * inset)
    lo = np.column_stack([footprint, np.full(4, eave)])
    hi = np.column_stack([inner, np.full(4, eave + height)])
    slopes = [_face(np.stack([lo[i], lo[(i + 1) % 4], hi[(i + 1) % 4], hi[i]]))
              for i in range(4)]
    top = PlanarFace((hi,), UP, SemanticClass.ROOF)
    return BuildingLayout(
        footprint_xy=footprint, walls=walls, other_faces=[ground_face(footprint), *slopes, top],
        floors=n, height_m=eave + height,
        extra={"roof": {"kind": "mansard", "eave_height_m": eave, "mansard_height_m": height,
                        "pitch_deg": MANSARD_PITCH_DEG, "inset_m": float(inset)}},
    )
