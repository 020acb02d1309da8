"""Cut the faces of a building's bodies where another body's face lies against them.

BIM solids touch: a wall butts against the side of another at a corner, a window lining
lies against its reveal. The part of a face covered by a touching body is inside the
building, the rest may be facade; the visibility test (:mod:`dataset.visibility`) decides a
face as a whole, so :func:`split_touching_faces` first cuts each face along the outline of
the opposite-facing coplanar faces that cover it. The pieces are triangulated with shapely's
constrained Delaunay triangulation; nothing else changes.
"""

from __future__ import annotations

import numpy as np
import shapely
from shapely.geometry import Polygon

from dataset.mesh import LabelledMesh

PLANE_DECIMALS_NORMAL = 6  # faces whose unit normals agree to 1e-6 are parallel
PLANE_DECIMALS_OFFSET_M = 5  # ... and whose plane offsets agree to 10 um, coplanar
MIN_PIECE_M2 = 1e-8  # covered or uncovered parts smaller than this are ignored
BOX_TOLERANCE_M = 1e-9  # bounding boxes that overlap by less than this do not touch


def split_touching_faces(
    mesh: LabelledMesh, which: np.ndarray
) -> tuple[LabelledMesh, np.ndarray]:
    """Cut faces in ``which`` along the outline of the coplanar faces that face them.

    Parameters
    ----------
    mesh
        The building: faces of touching bodies, z up, metres.
    which : (F,) bool
        Faces to cut (the facade candidates); any face may cover them.

    Returns
    -------
    mesh
        Faces not cut in their order, then the pieces of each cut face (its label, facade
        id and orientation).
    parent : (F',) int64
        Index of each output face's face in the input.
    """
    normals = mesh.face_normals()
    tri = mesh.triangles_m
    offsets = np.einsum("ij,ij->i", normals, tri[:, 0])
    lo, hi = tri.min(axis=1), tri.max(axis=1)
    basis_u, basis_v = _plane_bases(normals)
    extent = hi - lo  # a face flat along an axis overlaps along it whatever its bounds
    keys = np.concatenate([np.round(normals, PLANE_DECIMALS_NORMAL) + 0.0,
                           np.round(offsets, PLANE_DECIMALS_OFFSET_M)[:, None] + 0.0], axis=1)
    by_plane: dict[tuple[float, ...], list[int]] = {}
    for j, k in enumerate(map(tuple, keys)):
        by_plane.setdefault(k, []).append(j)
    new_vertices: list[np.ndarray] = []
    piece_parent: list[int] = []
    cut = np.zeros(len(tri), dtype=bool)
    for i in np.flatnonzero(which & (np.linalg.norm(normals, axis=1) > 0.5)):
        opposite = by_plane.get(tuple(-keys[i] + 0.0))
        if not opposite:
            continue
        opposite = np.asarray(opposite)
        overlap = np.all((lo[opposite] < hi[i] - BOX_TOLERANCE_M)
                         & (hi[opposite] > lo[i] + BOX_TOLERANCE_M)
                         | (extent[opposite] < BOX_TOLERANCE_M) | (extent[i] < BOX_TOLERANCE_M),
                         axis=1)
        opposite = opposite[overlap]
        if len(opposite) == 0:
            continue
        u, v = basis_u[i], basis_v[i]
        origin = tri[i, 0]
        uv = np.stack([u, v], axis=1)  # (3, 2)
        own = Polygon((tri[i] - origin) @ uv)
        others = shapely.polygons((tri[opposite] - origin) @ uv)
        cover = shapely.union_all(others).intersection(own)
        if cover.area < MIN_PIECE_M2 or own.area - cover.area < MIN_PIECE_M2:
            continue
        cut[i] = True
        for part in (cover, own.difference(cover)):
            triangles = shapely.get_parts(shapely.constrained_delaunay_triangles(part))
            xy = shapely.get_coordinates(shapely.get_exterior_ring(triangles)).reshape(-1, 4, 2)
            new_vertices.append(origin + xy[:, :3, :1] * u + xy[:, :3, 1:2] * v)  # (T, 3, 3)
            piece_parent.extend([int(i)] * len(xy))
    if not cut.any():
        return mesh, np.arange(len(tri))
    corners = np.concatenate(new_vertices)
    piece_parent_a = np.asarray(piece_parent, dtype=np.int64)
    # Each piece turns the way its parent does.
    turn = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    flip = np.einsum("ij,ij->i", turn, normals[piece_parent_a]) < 0
    corners[flip] = corners[flip][:, ::-1]
    keep = np.flatnonzero(~cut)
    parent = np.concatenate([keep, piece_parent_a])
    vertices = np.concatenate([mesh.vertices_m, corners.reshape(-1, 3)])
    pieces = len(mesh.vertices_m) + np.arange(3 * len(corners)).reshape(-1, 3)
    faces = np.concatenate([mesh.faces[keep], pieces])
    return LabelledMesh(vertices, faces, mesh.face_label[parent], mesh.face_facade[parent]), parent


def _plane_bases(normals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(F, 3) and (F, 3) unit vectors spanning each face's plane, right-handed with its
    (F, 3) unit normal (zero for a zero normal)."""
    helper = np.where(np.abs(normals[:, 2:3]) < 0.9, [[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]])
    u = np.cross(helper, normals)
    length = np.linalg.norm(u, axis=1, keepdims=True)
    u = np.divide(u, length, out=np.zeros_like(u), where=length > 0)
    return u, np.cross(normals, u)
