"""A CityGML building's facades and their exact areas, measured in each facade's plane.

A facade is a group of upright wall, window and door polygons facing one way, in one plane
(within the offset tolerance) and contiguous along the wall
(:func:`dataset.importers.mesh.facade_grouping.group_facades`, the mesh importer's grouping), that
holds wall polygons. Every ``WallSurface`` bounds the building against the outside by
definition, so no visibility test decides which walls count (unlike a BIM mesh).

Areas are regions in the facade's plane (u along the wall to the right seen from outside,
v = z above the ground), built with shapely:

- an opening (a ``Window`` or ``Door`` with all its polygons: glass, frame, mullions, sill)
  takes the union of its polygons projected onto the plane, less what a wall polygon in
  front of them hides (a frame modelled into the wall behind the reveal), so a window
  modelled with a hundred polygons counts once, as seen head-on; frames and sills count as
  window, its reveal sides (perpendicular to the wall) project to nothing; where openings
  overlap head-on, the one in front (mean depth along the normal) takes the overlap;
- a hole in a wall polygon that the openings cover by at least ``min_hole_cover`` is the
  opening's rough opening: the uncovered rim (the gap modellers leave between hole and
  frame) counts as that opening too and gets a filler surface in the wall's plane, so the
  rendered labels show what the truth counts;
- gross = walls (with their remaining holes) + openings, cut at the ground (v >= 0);
  window = the windows' region, door = the doors' region outside windows, wall = the rest.
"""

from __future__ import annotations

from dataclasses import dataclass

import mapbox_earcut
import numpy as np
import shapely
from shapely.geometry import MultiPolygon, Polygon, box

from dataset.importers.citygml.config import CityGmlConfig
from dataset.importers.citygml.polygons import MIN_AREA_M2, PolygonTriangles
from dataset.importers.mesh.facade_grouping import group_facades

_UP = np.array([0.0, 0.0, 1.0])
GRID_M = 1e-9
"""Every region operation snaps to this grid (1 nm): GEOS's floating overlay can return an
empty intersection for nearly coincident edges (it did for a door of 4018207), snap
rounding cannot."""
IN_FRONT_M = 0.001
"""A wall polygon this far (1 mm) or more in front of an opening's triangle hides it."""


@dataclass(frozen=True)
class Surface:
    """One triangulated polygon of a building, world frame (recentred), metres.

    ``kind`` and ``owner_id`` as in :class:`dataset.importers.citygml.read.CityPolygon`;
    ``rings_m`` its rings (exterior first), ``tri`` its triangles.
    """

    polygon_id: str
    kind: str
    owner_id: str
    rings_m: tuple[np.ndarray, ...]
    tri: PolygonTriangles


@dataclass(frozen=True)
class FacadeRegions:
    """One facade: its plane, members and regions (shapely, facade-plane u/v metres).

    ``normal`` outward horizontal unit vector, ``tangent`` = up x normal (u axis),
    ``offset_m`` the plane's distance from the origin along ``normal``. ``surfaces``: indices
    of its wall surfaces; ``openings``: owner ids of its windows and doors. ``fill_m``:
    filler triangles (T, 3, 3) in the walls' planes with their (T,) class kinds
    (``"window"``/``"door"``).
    """

    normal: np.ndarray
    tangent: np.ndarray
    offset_m: float
    surfaces: tuple[int, ...]
    openings: tuple[str, ...]
    gross: Polygon | MultiPolygon
    window: Polygon | MultiPolygon
    door: Polygon | MultiPolygon
    wall: Polygon | MultiPolygon
    fill_m: np.ndarray
    fill_kind: tuple[str, ...]

    def uv_m(self, points_m: np.ndarray) -> np.ndarray:
        """(N, 2) facade-plane coordinates of (N, 3) world points."""
        p = np.asarray(points_m, dtype=np.float64).reshape(-1, 3)
        return np.column_stack([p @ self.tangent, p[:, 2]])

    def world_m(self, uv_m: np.ndarray) -> np.ndarray:
        """(N, 3) points of the facade's reference plane at (N, 2) u/v."""
        uv = np.asarray(uv_m, dtype=np.float64).reshape(-1, 2)
        return uv[:, :1] * self.tangent + uv[:, 1:] * _UP + self.offset_m * self.normal

    def outline_m(self) -> np.ndarray:
        """(4, 3) bounding rectangle of the gross region in the reference plane: bottom-left,
        bottom-right, top-right, top-left seen from outside (counter-clockwise)."""
        u0, v0, u1, v1 = self.gross.bounds
        return self.world_m(np.array([[u0, v0], [u1, v0], [u1, v1], [u0, v1]]))


def building_facades(surfaces: list[Surface], config: CityGmlConfig
                     ) -> tuple[list[FacadeRegions], dict[str, int]]:
    """Facades of one building (ground at z = 0) and which facade each opening joined.

    Returns
    -------
    facades
        Ordered by azimuth of the normal (counter-clockwise from +x), then offset, then
        position along the wall (as :func:`group_facades`).
    opening_facade
        Opening owner id -> index into ``facades``; openings on no facade are absent.
    """
    facing = [i for i, s in enumerate(surfaces) if s.kind in ("wall", "window", "door")]
    tri = np.concatenate([surfaces[i].tri.vertices_m[surfaces[i].tri.faces] for i in facing])
    owner = np.concatenate([np.full(len(surfaces[i].tri.faces), i) for i in facing])
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    areas = 0.5 * np.linalg.norm(normals, axis=1)
    normals = normals / np.maximum(2 * areas, 1e-300)[:, None]
    groups = group_facades(
        tri, normals, areas, np.ones(len(tri), dtype=bool),
        max_tilt_deg=config.max_tilt_deg, angle_tolerance_deg=config.angle_tolerance_deg,
        offset_tolerance_m=config.offset_tolerance_m, gap_tolerance_m=config.gap_tolerance_m,
        min_width_m=config.min_facade_width_m)
    planes, members = [], []
    for g in groups:
        idx = np.unique(owner[g.face_index])
        walls = [int(i) for i in idx if surfaces[i].kind == "wall"]
        if walls:
            planes.append(g)
            members.append(walls)
    opening_facade = _assign_openings(surfaces, planes, tri, owner, areas, groups, config)
    facades = []
    for k, (g, walls) in enumerate(zip(planes, members)):
        openings = sorted(o for o, f in opening_facade.items() if f == k)
        facades.append(_regions(surfaces, g, walls, openings, config))
    return facades, opening_facade


def _assign_openings(surfaces, planes, tri, owner, areas, groups, config) -> dict[str, int]:
    """Opening owner id -> facade index: the facade whose group holds most of the opening's
    upright area, else the facade its projection overlaps most within
    ``max_opening_depth_m`` (a window set back further than the offset tolerance)."""
    plane_of_group = {id(g): k for k, g in enumerate(planes)}
    face_plane = np.full(len(tri), -1)
    for g in groups:
        if id(g) in plane_of_group:
            face_plane[g.face_index] = plane_of_group[id(g)]
    by_owner: dict[str, list[int]] = {}
    for i, s in enumerate(surfaces):
        if s.kind in ("window", "door"):
            by_owner.setdefault(s.owner_id, []).append(i)
    out: dict[str, int] = {}
    for opening, idx in sorted(by_owner.items()):
        in_opening = np.isin(owner, idx)
        votes = np.bincount(face_plane[in_opening & (face_plane >= 0)] ,
                            weights=areas[in_opening & (face_plane >= 0)],
                            minlength=len(planes))
        if len(votes) and votes.max() > 0:
            out[opening] = int(np.argmax(votes))
            continue
        best = _nearest_plane(tri[in_opening], areas[in_opening], planes, config)
        if best is not None:
            out[opening] = best
    return out


def _nearest_plane(tri, areas, planes, config) -> int | None:
    if not len(planes) or areas.sum() <= 0:
        return None
    centre = (tri.mean(axis=1) * areas[:, None]).sum(axis=0) / areas.sum()
    best, best_overlap = None, 0.0
    for k, g in enumerate(planes):
        n = np.asarray(g.normal)
        if abs(centre @ n - g.offset_m) > config.max_opening_depth_m:
            continue
        t = np.cross(_UP, n)
        along = tri[:, :, :2] @ t[:2]
        overlap = min(along.max(), g.along_m[1]) - max(along.min(), g.along_m[0])
        projected = _union_uv(tri, t).area
        if overlap > 0 and projected > best_overlap:
            best, best_overlap = k, projected
    return best


def _union_uv(tri_m: np.ndarray, tangent: np.ndarray) -> Polygon | MultiPolygon:
    """Union of (T, 3, 3) triangles projected onto the plane with u axis ``tangent``."""
    uv = np.stack([tri_m @ tangent, tri_m[:, :, 2]], axis=-1)  # (T, 3, 2)
    d1, d2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    keep = 0.5 * np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) >= MIN_AREA_M2
    return _polygonal(shapely.union_all(shapely.polygons(uv[keep]), grid_size=GRID_M))


def _visible_uv(tri_m: np.ndarray, walls: list[PolygonTriangles], wall_polys: list,
                n: np.ndarray, t: np.ndarray):
    """Projection of an opening's (T, 3, 3) triangles without what the facade's walls hide:
    a wall polygon more than :data:`IN_FRONT_M` in front of a triangle (a frame modelled
    into the reveal, behind the wall) covers it."""
    centre = tri_m.mean(axis=1)
    if not walls:
        return _union_uv(tri_m, t)
    origins = np.stack([w.origin_m for w in walls])
    normals = np.stack([w.normal for w in walls])
    # Distance along n from each triangle's centre to each wall's plane: > 0 means in front.
    ahead = (np.einsum("wk,wk->w", origins, normals)[None, :] - centre @ normals.T)
    ahead = ahead / np.where(np.abs(normals @ n) > 1e-6, normals @ n, np.inf)[None, :]
    front = ahead > IN_FRONT_M
    parts = []
    for mask in np.unique(front, axis=0):
        rows = np.all(front == mask, axis=1)
        region = _union_uv(tri_m[rows], t)
        if mask.any():
            hiding = shapely.union_all([wall_polys[j] for j in np.flatnonzero(mask)],
                                       grid_size=GRID_M)
            region = _polygonal(shapely.difference(region, hiding, grid_size=GRID_M))
        parts.append(region)
    return _polygonal(shapely.union_all(parts, grid_size=GRID_M))


def _polygon_uv(surface: Surface, tangent: np.ndarray):
    rings = [np.column_stack([r @ tangent, r[:, 2]]) for r in surface.rings_m]
    poly = Polygon(rings[0], rings[1:])
    return poly if poly.is_valid else shapely.make_valid(poly)


def _regions(surfaces, group, walls, openings, config) -> FacadeRegions:
    n = np.asarray(group.normal, dtype=np.float64)
    t = np.cross(_UP, n)
    wall_polys = [_polygon_uv(surfaces[i], t) for i in walls]
    wall_union = _polygonal(shapely.union_all(wall_polys, grid_size=GRID_M))
    regions: dict[str, list] = {"window": [], "door": []}
    opening_uv = {}
    depth = {}
    for o in openings:
        idx = [i for i, s in enumerate(surfaces) if s.owner_id == o and s.kind in
               ("window", "door")]
        tri = np.concatenate([surfaces[i].tri.vertices_m[surfaces[i].tri.faces] for i in idx])
        opening_uv[o] = (surfaces[idx[0]].kind,
                         _visible_uv(tri, [surfaces[i].tri for i in walls], wall_polys, n, t))
        area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
        depth[o] = float((tri.mean(axis=1) @ n * area).sum() / max(area.sum(), 1e-300))
    # Where openings overlap head-on (a door in front of shop glazing), the front one shows.
    taken = Polygon()
    for o in sorted(opening_uv, key=lambda o: (-depth[o], o)):
        kind, region = opening_uv[o]
        regions[kind].append(_polygonal(shapely.difference(region, taken, grid_size=GRID_M)))
        taken = _polygonal(shapely.union(taken, region, grid_size=GRID_M))
    covered = _polygonal(shapely.union_all([r for _, r in opening_uv.values()],
                                           grid_size=GRID_M))
    fill_tris, fill_kind = [], []
    for i, poly in zip(walls, wall_polys):
        for hole in _holes(poly):
            if hole.area < MIN_AREA_M2:
                continue
            if _area(shapely.intersection(hole, covered, grid_size=GRID_M)) < (
                    config.min_hole_cover * hole.area):
                continue
            kind = max(opening_uv.values(), key=lambda kr: _area(
                shapely.intersection(kr[1], hole, grid_size=GRID_M)))[0]
            rim = _polygonal(shapely.difference(hole, covered, grid_size=GRID_M))
            regions[kind].append(rim)
            tris = _lift(_triangulate_uv(rim), surfaces[i].tri, n, t)
            fill_tris.append(tris)
            fill_kind += [kind] * len(tris)
    window = _polygonal(shapely.union_all(regions["window"], grid_size=GRID_M))
    door = _polygonal(shapely.difference(  # a hole's rim: the window wins
        shapely.union_all(regions["door"], grid_size=GRID_M), window, grid_size=GRID_M))
    gross = _polygonal(shapely.union_all([wall_union, window, door], grid_size=GRID_M))
    u0, _, u1, v1 = gross.bounds
    above = box(u0 - 1.0, 0.0, u1 + 1.0, max(v1, 0.0) + 1.0)
    gross, window, door = (_polygonal(shapely.intersection(r, above, grid_size=GRID_M))
                           for r in (gross, window, door))
    wall = _polygonal(shapely.difference(
        gross, shapely.union_all([window, door], grid_size=GRID_M), grid_size=GRID_M))
    return FacadeRegions(
        normal=n, tangent=t, offset_m=float(group.offset_m), surfaces=tuple(walls),
        openings=tuple(openings), gross=gross, window=window, door=door, wall=wall,
        fill_m=np.concatenate(fill_tris) if fill_tris else np.zeros((0, 3, 3)),
        fill_kind=tuple(fill_kind))


def _polygonal(geometry):
    """The polygons of an overlay's result (snap rounding can leave collapsed lines and
    points beside them, which a later overlay refuses as mixed-dimension input)."""
    parts = [g for g in shapely.get_parts(geometry) if isinstance(g, Polygon) and not g.is_empty]
    return shapely.union_all(parts, grid_size=GRID_M) if parts else Polygon()


def _area(geometry) -> float:
    return float(shapely.area(geometry))


def _holes(poly) -> list[Polygon]:
    parts = getattr(poly, "geoms", [poly])
    return [Polygon(h) for p in parts if isinstance(p, Polygon) for h in p.interiors]


def _triangulate_uv(region) -> np.ndarray:
    """(T, 3, 2) triangles covering a shapely (multi)polygon exactly."""
    out = []
    for poly in getattr(region, "geoms", [region]):
        if not isinstance(poly, Polygon) or poly.area < MIN_AREA_M2:
            continue
        rings = [np.asarray(poly.exterior.coords)[:-1]]
        rings += [np.asarray(h.coords)[:-1] for h in poly.interiors]
        pts = np.concatenate(rings)
        ends = np.cumsum([len(r) for r in rings]).astype(np.uint32)
        idx = np.asarray(mapbox_earcut.triangulate_float64(pts, ends), dtype=np.int64)
        out.append(pts[idx.reshape(-1, 3)])
    return np.concatenate(out) if out else np.zeros((0, 3, 2))


def _lift(tri_uv: np.ndarray, plane: PolygonTriangles, n: np.ndarray, t: np.ndarray
          ) -> np.ndarray:
    """(T, 3, 3) points of ``plane`` (a wall polygon's) that project to (T, 3, 2) u/v along
    the facade normal ``n``, wound counter-clockwise about the wall's outward normal."""
    base = tri_uv[..., :1] * t + tri_uv[..., 1:] * _UP
    s = ((plane.origin_m - base) @ plane.normal) / float(n @ plane.normal)
    tri = base + s[..., None] * n
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    keep = 0.5 * np.linalg.norm(cross, axis=1) >= MIN_AREA_M2
    tri, cross = tri[keep], cross[keep]
    flip = cross @ plane.normal < 0
    tri[flip] = tri[flip][:, ::-1]
    return tri
