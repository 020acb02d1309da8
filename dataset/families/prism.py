"""Extrude a footprint polygon into walls, and close it with a ground face and a roof.

Footprints are counter-clockwise (n, 2) world x/y arrays; edge i runs from
vertex i to vertex i + 1 and its wall faces outward (right of the edge). Roof
variants:

- ``parapet``: walls rise ``parapet_height_m`` above the flat roof; a parapet of
  thickness ``parapet_thickness_m`` (top and inner faces: class roof) rings the roof.
- ``overhang``: a roof slab of ``thickness_m`` sits on the walls and sticks out
  ``overhang_m`` all round (soffit, sides and top: class roof).
- ``gable``: for rectangles only; two slopes meet at a ridge parallel to edge 0;
  the gable triangles belong to the walls of edges 1 and 3 (see :func:`gable_walls`).
"""

from __future__ import annotations

import numpy as np
import shapely
from shapely.geometry import Polygon

from dataset.families.facade_geometry import Opening, WallFrame, WallSpec, rectangle_outline
from dataset.families.polygon_mesh import PlanarFace, swept_faces, vertical_quad
from envelope.classes import SemanticClass

UP = np.array([0.0, 0.0, 1.0])
DOWN = np.array([0.0, 0.0, -1.0])


def validate_footprint(footprint_xy: np.ndarray) -> np.ndarray:
    """The footprint as a float (n, 2) array; ValueError unless simple and counter-clockwise."""
    fp = np.asarray(footprint_xy, dtype=np.float64)
    if fp.ndim != 2 or fp.shape[1] != 2 or len(fp) < 3:
        raise ValueError(f"footprint must have shape (n >= 3, 2), got {fp.shape}")
    poly = Polygon(fp)
    if not poly.is_valid or poly.area <= 0:
        raise ValueError("footprint must be a simple polygon with positive area")
    if not poly.exterior.is_ccw:
        raise ValueError("footprint must be counter-clockwise (walls face right of each edge)")
    return fp


def edge_frames(footprint_xy: np.ndarray) -> list[WallFrame]:
    """One :class:`WallFrame` per footprint edge i -> i + 1."""
    fp = validate_footprint(footprint_xy)
    nxt = np.roll(fp, -1, axis=0)
    return [WallFrame(tuple(p), tuple(q)) for p, q in zip(fp.tolist(), nxt.tolist())]


def prism_walls(
    footprint_xy: np.ndarray,
    wall_height_m: float,
    facade_ids: list[int],
    openings: list[list[Opening]] | None = None,
    contacts: list[list[tuple[float, float, float, float]]] | None = None,
) -> list[WallSpec]:
    """Rectangular walls of height ``wall_height_m`` over every footprint edge.

    ``facade_ids[i]``, ``openings[i]`` and ``contacts[i]`` belong to edge i;
    several edges may share a facade id (a faceted curved wall).
    """
    frames = edge_frames(footprint_xy)
    n = len(frames)
    openings = openings if openings is not None else [[] for _ in range(n)]
    contacts = contacts if contacts is not None else [[] for _ in range(n)]
    if not (len(facade_ids) == len(openings) == len(contacts) == n):
        raise ValueError(f"need one facade id, opening list and contact list per edge ({n})")
    if wall_height_m <= 0:
        raise ValueError(f"wall height must be > 0 m, got {wall_height_m}")
    return [
        WallSpec(f, fid, rectangle_outline(f.length_m, wall_height_m), tuple(o), tuple(c))
        for f, fid, o, c in zip(frames, facade_ids, openings, contacts)
    ]


def _ring_3d(ring_xy: np.ndarray, z_m: float) -> np.ndarray:
    return np.column_stack([ring_xy, np.full(len(ring_xy), z_m)])


def _drop_collinear(ring_xy: np.ndarray) -> np.ndarray:
    """Remove vertices that lie on the line through their neighbours (earcut would skip them)."""
    prev, nxt = np.roll(ring_xy, 1, axis=0), np.roll(ring_xy, -1, axis=0)
    a, b = ring_xy - prev, nxt - ring_xy
    cross = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    scale = np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1)
    return ring_xy[np.abs(cross) > 1e-9 * scale]


def offset_ring(footprint_xy: np.ndarray, distance_m: float) -> np.ndarray:
    """(m, 2) counter-clockwise ring of the footprint offset by ``distance_m`` (mitred corners).

    Positive grows the polygon, negative shrinks it.
    """
    grown = Polygon(footprint_xy).buffer(distance_m, join_style="mitre", mitre_limit=10.0)
    if not isinstance(grown, Polygon) or grown.is_empty:
        raise ValueError(
            f"offsetting the footprint by {distance_m} m splits or removes it; use a smaller offset"
        )
    ring = np.asarray(shapely.orient_polygons(grown).exterior.coords)[:-1]
    return _drop_collinear(ring)


def ground_face(footprint_xy: np.ndarray) -> PlanarFace:
    """The building's underside at z = 0 (class other: never seen, closes the solid)."""
    return PlanarFace((_ring_3d(footprint_xy, 0.0),), DOWN, SemanticClass.OTHER)


def parapet_roof_faces(
    footprint_xy: np.ndarray, roof_z_m: float, parapet_height_m: float, parapet_thickness_m: float
) -> list[PlanarFace]:
    """Flat roof at ``roof_z_m`` ringed by a parapet; walls must reach roof + parapet height."""
    if parapet_height_m <= 0 or parapet_thickness_m <= 0:
        raise ValueError("parapet height and thickness must be > 0 m")
    top_z = roof_z_m + parapet_height_m
    inner = offset_ring(footprint_xy, -parapet_thickness_m)
    faces = [
        PlanarFace((_ring_3d(footprint_xy, top_z), _ring_3d(inner, top_z)), UP, SemanticClass.ROOF),
        PlanarFace((_ring_3d(inner, roof_z_m),), UP, SemanticClass.ROOF),
    ]
    # Walking the inner ring backwards puts the roof on the right: the faces look inward.
    rev = inner[::-1]
    for p, q in zip(rev, np.roll(rev, -1, axis=0)):
        faces.append(vertical_quad(p, q, roof_z_m, top_z, label=SemanticClass.ROOF))
    return faces


def overhang_roof_faces(
    footprint_xy: np.ndarray, wall_top_z_m: float, overhang_m: float, thickness_m: float
) -> list[PlanarFace]:
    """Flat roof slab on top of the walls, sticking out ``overhang_m`` beyond them."""
    if overhang_m <= 0 or thickness_m <= 0:
        raise ValueError("roof overhang and thickness must be > 0 m")
    top_z = wall_top_z_m + thickness_m
    outer = offset_ring(footprint_xy, overhang_m)
    faces = [
        PlanarFace(
            (_ring_3d(outer, wall_top_z_m), _ring_3d(footprint_xy, wall_top_z_m)),
            DOWN,
            SemanticClass.ROOF,
        ),
        PlanarFace((_ring_3d(outer, top_z),), UP, SemanticClass.ROOF),
    ]
    for p, q in zip(outer, np.roll(outer, -1, axis=0)):
        faces.append(vertical_quad(p, q, wall_top_z_m, top_z, label=SemanticClass.ROOF))
    return faces


def gable_walls(
    footprint_xy: np.ndarray,
    eave_height_m: float,
    ridge_height_m: float,
    facade_ids: list[int],
    openings: list[list[Opening]] | None = None,
) -> list[WallSpec]:
    """Walls of a rectangle under a gable roof whose ridge runs parallel to edge 0.

    Edges 0 and 2 get rectangles up to the eaves; edges 1 and 3 get pentagons
    (rectangle + gable triangle up to the ridge), so the gables are wall of their facade.
    """
    frames = edge_frames(footprint_xy)
    if len(frames) != 4 or not np.isclose(frames[0].u_axis @ frames[1].u_axis, 0.0, atol=1e-9):
        raise ValueError("a gable roof needs a rectangular footprint (4 edges at right angles)")
    if not 0 < eave_height_m < ridge_height_m:
        raise ValueError(
            f"gable roof needs 0 < eave < ridge height, got {eave_height_m}, {ridge_height_m}"
        )
    openings = openings if openings is not None else [[] for _ in range(4)]
    walls = []
    for i, frame in enumerate(frames):
        width = frame.length_m
        if i % 2 == 0:
            outline = rectangle_outline(width, eave_height_m)
        else:
            outline = np.array(
                [[0.0, 0.0], [width, 0.0], [width, eave_height_m],
                 [width / 2, ridge_height_m], [0.0, eave_height_m]]
            )
        walls.append(WallSpec(frame, facade_ids[i], outline, tuple(openings[i])))
    return walls


def gable_roof_faces(walls: list[WallSpec]) -> list[PlanarFace]:
    """The two roof slopes over :func:`gable_walls`, sharing their eave and gable edges."""
    eave = walls[0].outline_uv[2, 1]
    ridge = walls[1].outline_uv[3, 1]
    faces = []
    for low, high_a, high_b in ((0, 3, 1), (2, 1, 3)):
        e = walls[low].frame
        eave_pts = e.points_m(np.array([[0.0, eave], [e.length_m, eave]]))
        ridge_end = _gable_apex(walls[high_b], ridge)
        ridge_start = _gable_apex(walls[high_a], ridge)
        ring = np.concatenate([eave_pts, ridge_end, ridge_start])
        normal = np.cross(ring[1] - ring[0], ring[2] - ring[1])
        faces.append(PlanarFace((ring,), normal / np.linalg.norm(normal), SemanticClass.ROOF))
    return faces


def _gable_apex(wall: WallSpec, ridge_height_m: float) -> np.ndarray:
    """(1, 3) apex of a gable wall, computed as the wall computes it (exact vertex sharing)."""
    return wall.frame.points_m(np.array([[wall.frame.length_m / 2, ridge_height_m]]))


def gable_roof_shell_faces(
    walls: list[WallSpec], overhang_m: float, thickness_m: float, gap_m: float
) -> tuple[list[PlanarFace], float]:
    """A roof slab over :func:`gable_walls` that overhangs eaves and gables, as its own body.

    The slab floats ``gap_m`` (measured perpendicular to the slopes) above the roof
    planes, so it shares no face or vertex with the house, and sticks out
    ``overhang_m`` (horizontally) beyond every wall. Class roof.

    Returns the faces and the height of the slab's top at the ridge, metres.
    """
    if min(overhang_m, thickness_m, gap_m) <= 0:
        raise ValueError("roof shell overhang, thickness and gap must be > 0 m")
    eave = float(walls[0].outline_uv[2, 1])
    ridge = float(walls[1].outline_uv[3, 1])
    along, length = walls[0].frame.u_axis, walls[0].frame.length_m
    across, depth = -walls[0].frame.normal, walls[1].frame.length_m
    half = depth / 2
    cos = half / np.hypot(half, ridge - eave)
    lift, thick = gap_m / cos, thickness_m / cos

    def under_z(s: float) -> float:
        return eave + lift + (ridge - eave) * (1 - abs(s - half) / half)

    section = [(s, under_z(s)) for s in (-overhang_m, half, depth + overhang_m)]
    section += [(s, z + thick) for s, z in reversed(section)]
    origin = np.array([*walls[0].frame.p0_xy, 0.0]) - overhang_m * along
    ring = np.array([origin + s * across + [0.0, 0.0, z] for s, z in section])
    faces = swept_faces(ring, (length + 2 * overhang_m) * along, label=SemanticClass.ROOF)
    return faces, under_z(half) + thick
