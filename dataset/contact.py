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
from shapely.ops import unary_union

from dataset.mesh import LabelledMesh

PLANE_DECIMALS_NORMAL = 6  # faces whose unit normals agree to 1e-6 are parallel
PLANE_DECIMALS_OFFSET_M = 5  # ... and whose plane offsets agree to 10 um, coplanar
MIN_PIECE_M2 = 1e-8  # covered or uncovered parts smaller than this are ignored


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
    keys = np.concatenate([np.round(normals, PLANE_DECIMALS_NORMAL) + 0.0,
                           np.round(offsets, PLANE_DECIMALS_OFFSET_M)[:, None] + 0.0], axis=1)
    by_plane: dict[tuple[float, ...], list[int]] = {}
    for j, k in enumerate(map(tuple, keys)):
        by_plane.setdefault(k, []).append(j)
    new_vertices: list[np.ndarray] = []
    pieces: list[np.ndarray] = []
    piece_parent: list[int] = []
    cut = np.zeros(len(tri), dtype=bool)
    for i in np.flatnonzero(which & (np.linalg.norm(normals, axis=1) > 0.5)):
        opposite = by_plane.get(tuple(-keys[i] + 0.0))
        if not opposite:
            continue
        u, v = _plane_basis(normals[i])
        origin = tri[i, 0]
        own = Polygon((tri[i] - origin) @ np.stack([u, v], axis=1))
        cover = unary_union([Polygon((tri[j] - origin) @ np.stack([u, v], axis=1))
                             for j in opposite]).intersection(own)
        if cover.area < MIN_PIECE_M2 or own.area - cover.area < MIN_PIECE_M2:
            continue
        cut[i] = True
        for part in (cover, own.difference(cover)):
            for t in shapely.get_parts(shapely.constrained_delaunay_triangles(part)):
                xy = np.asarray(t.exterior.coords)[:3]
                corners = origin + xy[:, :1] * u + xy[:, 1:2] * v
                if np.dot(np.cross(corners[1] - corners[0], corners[2] - corners[0]),
                          normals[i]) < 0:
                    corners = corners[::-1]
                pieces.append(np.arange(3) + len(mesh.vertices_m) + 3 * len(new_vertices))
                new_vertices.append(corners)
                piece_parent.append(int(i))
    if not cut.any():
        return mesh, np.arange(len(tri))
    keep = np.flatnonzero(~cut)
    parent = np.concatenate([keep, np.asarray(piece_parent, dtype=np.int64)])
    vertices = np.concatenate([mesh.vertices_m, np.concatenate(new_vertices)])
    faces = np.concatenate([mesh.faces[keep], np.stack(pieces)])
    return LabelledMesh(vertices, faces, mesh.face_label[parent], mesh.face_facade[parent]), parent


def _plane_basis(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors (3,) spanning the plane with this unit normal, right-handed with it."""
    helper = np.array([0.0, 0.0, 1.0]) if abs(normal[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    u = np.cross(helper, normal)
    u /= np.linalg.norm(u)
    return u, np.cross(normal, u)
