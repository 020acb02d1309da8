"""One CityGML polygon (exterior ring + holes, 3D) -> exact triangles, its plane and its area.

The plane is the exterior ring's Newell normal through its centroid; the normal's side is
the ring's orientation (counter-clockwise seen from outside, as CityGML's boundary
surfaces are written). Rings go to 2D in that plane (:func:`plane_basis`), shapely checks
them and mapbox_earcut triangulates them with their holes; the triangles keep the ring
vertices' own 3D positions, so a planar polygon's triangles cover it exactly.

Two defects are repaired and reported, because exporters write them and a user expects the
building anyway: a polygon whose corners stray more than :data:`PLANARITY_TOLERANCE_M` from
its plane (triangulated as it stands, each triangle through its own corners) and a
self-intersecting or self-touching one (shapely's ``make_valid`` of its 2D rings, triangles
then lie in the plane).
"""

from __future__ import annotations

from dataclasses import dataclass

import mapbox_earcut
import numpy as np
import shapely
from shapely.geometry import MultiPolygon, Polygon

from dataset.families.polygon_mesh import plane_basis
from envelope.polygons import newell_vector

PLANARITY_TOLERANCE_M = 0.01
"""A corner further than this from its polygon's plane makes the polygon non-planar (1 cm:
the ISO 19107 planarity that CityGML validators such as CityDoctor check by default)."""
MIN_AREA_M2 = 1e-9
"""Polygons (and triangles) with less area than this are dropped: nothing to see or count."""


@dataclass(frozen=True)
class PolygonTriangles:
    """A polygon's triangles.

    Attributes
    ----------
    vertices_m : (V, 3) float64
    faces : (T, 3) int64
        Counter-clockwise seen from the side ``normal`` points to.
    normal : (3,) float64
        Unit normal of the polygon's plane (outward for a boundary surface).
    origin_m : (3,) float64
        A point of the plane (the exterior ring's centroid).
    area_m2 : float
        Area of the polygon in its plane (exterior minus holes, after repair).
    non_planar : bool
        Some corner lies further than :data:`PLANARITY_TOLERANCE_M` from the plane.
    repaired : bool
        The 2D rings were invalid (self-intersecting, a hole outside) and were made valid.
    """

    vertices_m: np.ndarray
    faces: np.ndarray
    normal: np.ndarray
    origin_m: np.ndarray
    area_m2: float
    non_planar: bool
    repaired: bool


def triangulate_polygon(rings_m: tuple[np.ndarray, ...]) -> PolygonTriangles | None:
    """Triangulate one polygon (exterior ring, then holes; (n, 3) metres each).

    Returns None for a polygon without area (a ring along a line).
    """
    exterior = np.asarray(rings_m[0], dtype=np.float64)
    n_vec = newell_vector(exterior)
    length = float(np.linalg.norm(n_vec))
    if length < 2 * MIN_AREA_M2:
        return None
    normal = n_vec / length
    origin = exterior.mean(axis=0)
    basis = plane_basis(normal)  # (2, 3): u, v with u x v = normal
    rings = [np.asarray(r, dtype=np.float64) for r in rings_m]
    points = np.concatenate(rings)
    non_planar = bool(np.abs((points - origin) @ normal).max() > PLANARITY_TOLERANCE_M)
    rings_2d = [(r - origin) @ basis.T for r in rings]
    polygon = Polygon(rings_2d[0], rings_2d[1:])
    if polygon.is_valid:
        ends = np.cumsum([len(r) for r in rings]).astype(np.uint32)
        faces = np.asarray(mapbox_earcut.triangulate_float64(np.concatenate(rings_2d), ends),
                           dtype=np.int64).reshape(-1, 3)
        vertices, area, repaired = points, float(polygon.area), False
    else:
        vertices, faces, area = _triangulate_repaired(polygon, origin, basis)
        repaired = True
    if len(faces) == 0 or area < MIN_AREA_M2:
        return None
    faces = _facing(vertices, faces, normal)
    return PolygonTriangles(vertices, faces, normal, origin, area, non_planar, repaired)


def polygon_area_m2(rings_m: tuple[np.ndarray, ...]) -> float:
    """Area of a polygon in its own plane (exterior minus holes), m², as
    :func:`triangulate_polygon` measures it; 0 for a degenerate one."""
    tri = triangulate_polygon(rings_m)
    return 0.0 if tri is None else tri.area_m2


def _triangulate_repaired(polygon: Polygon, origin: np.ndarray, basis: np.ndarray
                          ) -> tuple[np.ndarray, np.ndarray, float]:
    """Triangles of ``make_valid(polygon)``'s polygonal parts, lifted into the plane."""
    fixed = shapely.make_valid(polygon)
    parts = [g for g in getattr(fixed, "geoms", [fixed]) if isinstance(g, Polygon | MultiPolygon)]
    vertices, faces, n = [], [], 0
    area = 0.0
    for part in parts:
        for poly in getattr(part, "geoms", [part]):
            if poly.area < MIN_AREA_M2:
                continue
            poly = shapely.orient_polygons(poly)
            rings = [np.asarray(poly.exterior.coords)[:-1]]
            rings += [np.asarray(h.coords)[:-1] for h in poly.interiors]
            ends = np.cumsum([len(r) for r in rings]).astype(np.uint32)
            pts_2d = np.concatenate(rings)
            tri = np.asarray(mapbox_earcut.triangulate_float64(pts_2d, ends),
                             dtype=np.int64).reshape(-1, 3)
            vertices.append(origin + pts_2d @ basis)
            faces.append(tri + n)
            n += len(pts_2d)
            area += float(poly.area)
    if not faces:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), 0.0
    return np.concatenate(vertices), np.concatenate(faces), area


def _facing(vertices_m: np.ndarray, faces: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """``faces`` without degenerate triangles, each wound counter-clockwise about ``normal``."""
    t = vertices_m[faces]
    cross = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    keep = 0.5 * np.linalg.norm(cross, axis=1) >= MIN_AREA_M2
    faces, cross = faces[keep], cross[keep]
    flip = cross @ normal < 0
    faces = faces.copy()
    faces[flip] = faces[flip][:, ::-1]
    return faces
