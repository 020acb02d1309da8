"""Labelled planar polygons in 3D -> one watertight labelled triangle mesh.

Buildings are assembled from planar faces (a wall with its openings as holes, a
reveal quad, a roof polygon). Each face is triangulated on its own with
mapbox_earcut, using only its ring vertices, and equal vertices of different
faces are merged afterwards. Faces that are built to share edges (same corner
coordinates computed the same way) therefore join without T-junctions, so the
result is a closed manifold wherever the faces close a solid.
"""

from __future__ import annotations

from dataclasses import dataclass

import mapbox_earcut
import numpy as np
import shapely
from shapely.geometry import Polygon

from envelope.classes import NO_FACADE, NUM_CLASSES
from envelope.mesh import MERGE_DECIMALS, LabelledMesh
from envelope.polygons import newell_vector

COLLINEAR_TOL_M = 1e-7
"""A vertex closer than this to a triangle edge lies on it (earcut leaves such T-junctions and
zero-area triangles where openings line up, e.g. sills at one height)."""
"""Vertices equal after rounding to 1 nm are one vertex (generators compute shared corners
with the same arithmetic, so they agree to far better than this)."""


@dataclass(frozen=True)
class PlanarFace:
    """One planar polygon (possibly with holes) of a building surface.

    Attributes
    ----------
    rings_m : tuple of (n, 3) float64
        World-frame metres; the first ring is the exterior, the others holes.
        Ring orientation does not matter: ``normal`` fixes the side.
    normal : (3,) float64
        Outward unit normal (the side the surface faces, away from the solid).
    label : int
        Semantic class id (:class:`envelope.classes.SemanticClass`).
    facade_id : int
        Facade id from 1, or :data:`envelope.classes.NO_FACADE` (0).
    """

    rings_m: tuple[np.ndarray, ...]
    normal: np.ndarray
    label: int
    facade_id: int = NO_FACADE

    def __post_init__(self) -> None:
        rings = tuple(np.asarray(r, dtype=np.float64) for r in self.rings_m)
        if not rings or any(r.ndim != 2 or r.shape[1] != 3 or len(r) < 3 for r in rings):
            raise ValueError("a planar face needs rings of shape (n >= 3, 3)")
        normal = np.asarray(self.normal, dtype=np.float64)
        length = float(np.linalg.norm(normal))
        if normal.shape != (3,) or abs(length - 1.0) > 1e-9:
            raise ValueError(f"face normal must be a (3,) unit vector, got {self.normal}")
        if not 0 <= int(self.label) < NUM_CLASSES:
            raise ValueError(f"unknown class id {self.label}")
        if self.facade_id < 0:
            raise ValueError(f"facade id must be >= 0, got {self.facade_id}")
        object.__setattr__(self, "rings_m", rings)
        object.__setattr__(self, "normal", normal)


def plane_basis(normal: np.ndarray) -> np.ndarray:
    """(2, 3) orthonormal in-plane axes (u, v) with u x v = ``normal`` (unit, (3,))."""
    n = np.asarray(normal, dtype=np.float64)
    helper = np.array([0.0, 0.0, 1.0]) if abs(n[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    u = _cross_3d(helper, n)
    u /= np.linalg.norm(u)
    return np.stack([u, _cross_3d(n, u)])


def face_polygon_2d(face: PlanarFace) -> Polygon:
    """Shapely polygon of ``face`` in its plane coordinates (:func:`plane_basis`), metres."""
    basis = plane_basis(face.normal)
    rings = [r @ basis.T for r in face.rings_m]
    return Polygon(rings[0], rings[1:])


def _triangulate_face(face: PlanarFace) -> tuple[np.ndarray, np.ndarray]:
    """Triangles of one face: (T, 3) indices into its stacked ring vertices, and those (N, 3)."""
    points = np.concatenate(face.rings_m)
    points_2d = points @ plane_basis(face.normal).T
    ends = np.cumsum([len(r) for r in face.rings_m]).astype(np.uint32)
    tri = np.asarray(mapbox_earcut.triangulate_float64(points_2d, ends), dtype=np.int64)
    tri = tri.reshape(-1, 3)
    if len(face.rings_m) > 1 or len(points) > 4:  # a lone triangle or quad has no T-junction
        tri = _repair_t_junctions(points_2d, tri)
    if len(tri) == 0:
        raise ValueError(f"face with {len(points)} vertices has no area to triangulate")
    t = points[tri]
    facing = _cross_3d(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]) @ face.normal
    flip = facing < 0
    tri[flip] = tri[flip][:, ::-1]
    return tri, points


def _cross_3d(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross product of (..., 3) vectors (np.cross is slow on the many tiny faces here)."""
    return np.stack(
        [a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
         a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
         a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]],
        axis=-1,
    )


def _cross_2d(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """z component of the cross product of (..., 2) vectors."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _repair_t_junctions(points_2d: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Drop zero-area triangles and split triangles at vertices lying inside their edges.

    points_2d is (N, 2), tri (T, 3) indices; returns (T', 3) covering the same area with every
    ring vertex a corner of the triangles around it, so neighbouring faces join edge to edge.
    """
    for _ in range(len(points_2d) + 1):
        t = points_2d[tri]
        area2 = np.abs(_cross_2d(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]))
        longest = np.max(np.linalg.norm(t - np.roll(t, -1, axis=1), axis=2), axis=1)
        tri = tri[area2 > COLLINEAR_TOL_M * longest]
        start = points_2d[tri]  # (T, 3, 2): edge k runs from corner k to corner k + 1
        d = np.roll(start, -1, axis=1) - start
        length = np.linalg.norm(d, axis=2)
        w = points_2d[None, None, :, :] - start[:, :, None, :]  # (T, 3, N, 2)
        along = np.einsum("tknc,tkc->tkn", w, d) / length[..., None]
        across = np.abs(_cross_2d(w, d[:, :, None, :])) / length[..., None]
        hit = (across < COLLINEAR_TOL_M) & (along > COLLINEAR_TOL_M)
        hit &= along < length[..., None] - COLLINEAR_TOL_M
        rows = np.flatnonzero(hit.any(axis=(1, 2)))
        if len(rows) == 0:
            return tri
        keep = np.ones(len(tri), dtype=bool)
        keep[rows] = False
        new = []
        for r in rows:
            k, m = np.argwhere(hit[r])[0]
            a, b, c = tri[r, k], tri[r, (k + 1) % 3], tri[r, (k + 2) % 3]
            new += [(a, m, c), (m, b, c)]
        tri = np.concatenate([tri[keep], np.array(new, dtype=np.int64)])
    raise ValueError("could not repair the triangulation of a face (self-overlapping rings?)")


def triangulate_faces(faces: list[PlanarFace]) -> LabelledMesh:
    """One labelled mesh from planar faces: earcut per face, then merge equal vertices.

    Vertices equal to :data:`MERGE_DECIMALS` decimals become one vertex; the
    result is deterministic (vertices sorted lexicographically).

    Raises
    ------
    ValueError
        If ``faces`` is empty or a face cannot be triangulated.
    """
    if not faces:
        raise ValueError("need at least one face to triangulate")
    all_points, all_tris, labels, facades = [], [], [], []
    offset = 0
    for face in faces:
        tri, points = _triangulate_face(face)
        all_points.append(points)
        all_tris.append(tri + offset)
        labels.append(np.full(len(tri), face.label, dtype=np.uint8))
        facades.append(np.full(len(tri), face.facade_id, dtype=np.int32))
        offset += len(points)
    points = np.round(np.concatenate(all_points), MERGE_DECIMALS) + 0.0  # no -0.0
    vertices, inverse = np.unique(points, axis=0, return_inverse=True)
    tris = inverse.reshape(-1)[np.concatenate(all_tris)]
    return LabelledMesh(vertices, tris, np.concatenate(labels), np.concatenate(facades))


def extruded_faces(
    polygon_xy: Polygon, z0_m: float, z1_m: float, *, label: int, facade_id: int = NO_FACADE
) -> list[PlanarFace]:
    """Closed vertical prism over a shapely polygon (holes allowed), from z0 to z1 metres.

    Returns the bottom, top and one quad per ring edge, all with outward normals.
    """
    if not z1_m > z0_m:
        raise ValueError(f"extrusion needs z1 > z0, got z0={z0_m}, z1={z1_m}")
    if polygon_xy.is_empty or not polygon_xy.is_valid:
        raise ValueError("extrusion needs a valid, non-empty polygon")
    poly = shapely.orient_polygons(polygon_xy)  # exterior CCW, holes CW: solid on the left
    rings_xy = [np.asarray(poly.exterior.coords)[:-1]] + [
        np.asarray(h.coords)[:-1] for h in poly.interiors
    ]

    def at(ring_xy: np.ndarray, z: float) -> np.ndarray:
        return np.column_stack([ring_xy, np.full(len(ring_xy), z)])

    down, up = np.array([0.0, 0.0, -1.0]), np.array([0.0, 0.0, 1.0])
    faces = [
        PlanarFace(tuple(at(r, z0_m) for r in rings_xy), down, label, facade_id),
        PlanarFace(tuple(at(r, z1_m) for r in rings_xy), up, label, facade_id),
    ]
    for ring in rings_xy:
        for p, q in zip(ring, np.roll(ring, -1, axis=0)):
            faces.append(vertical_quad(p, q, z0_m, z1_m, label=label, facade_id=facade_id))
    return faces


def vertical_quad(
    p_xy: np.ndarray, q_xy: np.ndarray, z0_m: float, z1_m: float, *, label: int,
    facade_id: int = NO_FACADE,
) -> PlanarFace:
    """Vertical rectangle over the segment p -> q, facing right of it (outward of a CCW ring)."""
    d = np.asarray(q_xy, dtype=np.float64) - np.asarray(p_xy, dtype=np.float64)
    normal = np.array([d[1], -d[0], 0.0]) / np.hypot(d[0], d[1])
    ring = np.array(
        [[p_xy[0], p_xy[1], z0_m], [q_xy[0], q_xy[1], z0_m],
         [q_xy[0], q_xy[1], z1_m], [p_xy[0], p_xy[1], z1_m]]
    )
    return PlanarFace((ring,), normal, label, facade_id)


def swept_faces(
    ring_m: np.ndarray, offset_m: np.ndarray, *, label: int, facade_id: int = NO_FACADE
) -> list[PlanarFace]:
    """Closed prism swept by a planar simple polygon along a vector perpendicular to it.

    Parameters
    ----------
    ring_m : (n, 3) float
        Corners of a simple planar polygon (either orientation), world metres.
    offset_m : (3,) float
        Sweep vector, perpendicular to the polygon's plane; its length is the prism's length.

    Returns the two caps and one quad per edge, all with outward normals.
    """
    ring = np.asarray(ring_m, dtype=np.float64)
    offset = np.asarray(offset_m, dtype=np.float64)
    length = float(np.linalg.norm(offset))
    if ring.ndim != 2 or ring.shape[1] != 3 or len(ring) < 3 or length <= 0:
        raise ValueError("a sweep needs an (n >= 3, 3) ring and a non-zero (3,) offset")
    d = offset / length
    newell = newell_vector(ring)
    if abs(newell @ d) < (1 - 1e-9) * np.linalg.norm(newell):
        raise ValueError("the sweep offset must be perpendicular to the ring's plane")
    # Seen from +d, a counter-clockwise ring has its outside to the right of each edge.
    side = 1.0 if newell @ d > 0 else -1.0
    faces = [
        PlanarFace((ring,), -d, label, facade_id),
        PlanarFace((ring + offset,), d, label, facade_id),
    ]
    for p, q in zip(ring, np.roll(ring, -1, axis=0)):
        n = side * _cross_3d(q - p, d)
        quad = np.stack([p, q, q + offset, p + offset])
        faces.append(PlanarFace((quad,), n / np.linalg.norm(n), label, facade_id))
    return faces
