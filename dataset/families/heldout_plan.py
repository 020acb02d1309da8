"""Held-out designs whose plans differ: ``corner``, ``bow`` and ``sawtooth``.

- ``corner``: a trapezoid whose east facade leans, so the plan has a ``corner_deg``
  (acute) and a 180° - ``corner_deg`` (obtuse) corner; a flat roof slab overhangs
  every wall. Facades 1 south (door), 2 the leaning east one, 3 north, 4 west.
- ``bow``: a block whose south front is one convex arc of radius ``radius_m``
  (a much flatter curve than the ``rounded`` model's half-round), faceted into
  planar segments of about :data:`FACET_TARGET_M` chord, each with one window per
  floor (the middle one a door on the ground floor). Facade 1 is the whole arc
  (``curved=True``), 2 east, 3 north, 4 west; parapet roof.
- ``sawtooth``: a block whose south-east corner steps back in :data:`STEPS` stairs
  of ``step_m``, so that side is many small facades (alternately facing south and
  east, one window column each); facade ids follow the plan's edges from the
  south-west corner; parapet roof.
"""

from __future__ import annotations

import numpy as np

from dataset.families.building_assembly import BuildingLayout
from dataset.families.facade_geometry import Opening, WallSpec, window_grid
from dataset.families.heldout_openings import (
    DOOR_HEIGHT_M,
    DOOR_THRESHOLD_M,
    SILL_M,
    wall_openings,
)
from dataset.families.heldout_params import HeldoutParams
from dataset.families.prism import (
    ground_face,
    overhang_roof_faces,
    parapet_roof_faces,
    prism_walls,
)

FACET_TARGET_M = 1.8
STEPS = 4
PARAPET_THICKNESS_M = 0.3
OVERHANG_M = 0.6
SLAB_THICKNESS_M = 0.3


def corner_footprint(width_m: float, depth_m: float, corner_deg: float) -> np.ndarray:
    """(4, 2) counter-clockwise trapezoid: the south edge ``width_m`` long, the east edge
    leaning in at ``corner_deg`` to it, the north edge shorter by ``depth_m / tan``."""
    shift = depth_m / np.tan(np.radians(corner_deg))
    if width_m - shift < 3.0:
        raise ValueError(f"a {corner_deg}° corner leaves the north facade under 3 m on "
                         f"{width_m} x {depth_m}")
    w, d = width_m / 2, depth_m / 2
    return np.array([[-w, -d], [w, -d], [w - shift, d], [-w, d]])


def plan_walls(footprint_xy: np.ndarray, params: HeldoutParams,
               wall_height_m: float) -> list[WallSpec]:
    """Walls of ``wall_height_m`` over every edge of ``footprint_xy``, facade i + 1 over edge i,
    each with its window grid; the door on facade 1."""
    lengths = np.linalg.norm(np.roll(footprint_xy, -1, axis=0) - footprint_xy, axis=1)
    openings = [wall_openings(float(length), params, door=i == 0)
                for i, length in enumerate(lengths)]
    return prism_walls(footprint_xy, wall_height_m, list(range(1, len(lengths) + 1)), openings)


def corner_layout(params: HeldoutParams) -> BuildingLayout:
    """Walls over the trapezoid, an overhanging roof slab and the ground."""
    footprint = corner_footprint(params.width_m, params.depth_m, params.corner_deg)
    top = params.floors * params.floor_height_m
    walls = plan_walls(footprint, params, top)
    roof = overhang_roof_faces(footprint, top, OVERHANG_M, SLAB_THICKNESS_M)
    return BuildingLayout(
        footprint_xy=footprint, walls=walls, other_faces=[ground_face(footprint), *roof],
        floors=params.floors, height_m=top + SLAB_THICKNESS_M,
        extra={"roof": {"kind": "overhang", "overhang_m": OVERHANG_M,
                        "thickness_m": SLAB_THICKNESS_M},
               "corner_deg": [params.corner_deg, 180.0 - params.corner_deg]},
    )


def bow_footprint(width_m: float, depth_m: float, radius_m: float) -> tuple[np.ndarray, int]:
    """(n, 2) counter-clockwise footprint and its number of arc facets.

    The south edge is an arc of ``radius_m`` through the rectangle's south corners,
    bulging south; its end points are written exactly (no trigonometry), so the
    east and west walls meet the first and last facet in shared vertices.
    """
    w, d = width_m / 2, depth_m / 2
    if radius_m <= w:
        raise ValueError(f"the bow's radius must exceed half its width, got {radius_m} <= {w}")
    centre_y = -d + np.sqrt(radius_m ** 2 - w ** 2)
    half_angle = np.arcsin(w / radius_m)
    facets = max(4, round(2 * half_angle * radius_m / FACET_TARGET_M))
    angles = -np.pi / 2 - half_angle + 2 * half_angle * np.arange(1, facets) / facets
    arc = np.column_stack([radius_m * np.cos(angles), centre_y + radius_m * np.sin(angles)])
    return np.concatenate([[[-w, -d]], arc, [[w, -d], [w, d], [-w, d]]]), facets


def bow_layout(params: HeldoutParams) -> BuildingLayout:
    """Walls (one curved facade of many facets), parapet roof and ground."""
    n, fh = params.floors, params.floor_height_m
    footprint, facets = bow_footprint(params.width_m, params.depth_m, params.radius_m)
    lengths = np.linalg.norm(np.roll(footprint, -1, axis=0) - footprint, axis=1)
    middle = facets // 2
    openings = []
    for k in range(facets):
        chord = float(lengths[k])
        width = min(params.window_width_m, chord - 0.5)
        grid = window_grid(chord, n, fh, columns=1, window_width_m=width,
                           window_height_m=params.window_height_m, sill_height_m=SILL_M,
                           margin_m=0.0, depth_m=params.reveal_m, first_floor=int(k == middle))
        if k == middle:
            grid.insert(0, Opening("door", chord / 2 - width / 2, DOOR_THRESHOLD_M,
                                   chord / 2 + width / 2, DOOR_THRESHOLD_M + DOOR_HEIGHT_M,
                                   params.reveal_m + 0.02))
        openings.append(grid)
    openings += [wall_openings(float(length), params) for length in lengths[facets:]]
    top = n * fh
    walls = prism_walls(footprint, top + params.roof_m, [1] * facets + [2, 3, 4], openings)
    roof = parapet_roof_faces(footprint, top, params.roof_m, PARAPET_THICKNESS_M)
    centre_y = -params.depth_m / 2 + np.sqrt(params.radius_m ** 2 - (params.width_m / 2) ** 2)
    return BuildingLayout(
        footprint_xy=footprint, walls=walls, other_faces=[ground_face(footprint), *roof],
        floors=n, height_m=top + params.roof_m, curved_facade_ids=frozenset({1}),
        extra={"roof": {"kind": "parapet", "parapet_height_m": params.roof_m,
                        "parapet_thickness_m": PARAPET_THICKNESS_M},
               "curved_facade": {"id": 1, "centre_xy_m": [0.0, float(centre_y)],
                                 "radius_m": params.radius_m, "facets": facets,
                                 "arc_deg": float(np.degrees(2 * np.arcsin(
                                     params.width_m / 2 / params.radius_m)))}},
    )


def sawtooth_footprint(width_m: float, depth_m: float, step_m: float) -> np.ndarray:
    """(n, 2) counter-clockwise footprint: the rectangle with its south-east corner cut
    into :data:`STEPS` stairs of ``step_m`` (each a north- then an east-going edge)."""
    cut = STEPS * step_m
    if min(width_m, depth_m) - cut < 2.0:
        raise ValueError(f"{STEPS} steps of {step_m} m leave under 2 m of straight wall on "
                         f"{width_m} x {depth_m}")
    w, d = width_m / 2, depth_m / 2
    x0 = w - cut
    points = [[-w, -d], [x0, -d]]
    for i in range(STEPS):
        points += [[x0 + i * step_m, -d + (i + 1) * step_m],
                   [x0 + (i + 1) * step_m, -d + (i + 1) * step_m]]
    points[-1][0] = w  # the last step ends on the east side exactly
    return np.array(points + [[w, d], [-w, d]])


def sawtooth_layout(params: HeldoutParams) -> BuildingLayout:
    """Walls over the stepped plan (one facade per edge), parapet roof and ground."""
    footprint = sawtooth_footprint(params.width_m, params.depth_m, params.step_m)
    top = params.floors * params.floor_height_m
    walls = plan_walls(footprint, params, top + params.roof_m)
    roof = parapet_roof_faces(footprint, top, params.roof_m, PARAPET_THICKNESS_M)
    return BuildingLayout(
        footprint_xy=footprint, walls=walls, other_faces=[ground_face(footprint), *roof],
        floors=params.floors, height_m=top + params.roof_m,
        extra={"roof": {"kind": "parapet", "parapet_height_m": params.roof_m,
                        "parapet_thickness_m": PARAPET_THICKNESS_M},
               "steps": {"count": STEPS, "step_m": params.step_m}},
    )
