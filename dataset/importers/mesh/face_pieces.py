"""Replace some faces of a mesh by pieces cut from them in their own plane.

Shared by :mod:`dataset.importers.mesh.contact` (faces cut where another body's face lies on
them) and :mod:`dataset.importers.mesh.crossings` (faces cut where other faces pass through
them): a face is cut in 2-D, in the plane coordinates ``(u, v)`` of
:func:`envelope.mesh.plane_bases` from its first corner; each piece is triangulated
with shapely's constrained Delaunay triangulation and keeps its parent's label, facade id
and orientation.
"""

from __future__ import annotations

import numpy as np
import shapely
from shapely.errors import GEOSException

from envelope.mesh import LabelledMesh, plane_bases

MIN_PIECE_M2 = 1e-8
"""Pieces smaller than this are dropped (and a cut leaving only such pieces is no cut)."""


def face_frames(mesh: LabelledMesh) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Every face's unit normal, plane basis ``u``, ``v`` and origin (its first corner);
    each (F, 3)."""
    normals = mesh.face_normals()
    u, v = plane_bases(normals)
    return normals, u, v, mesh.triangles_m[:, 0]


def face_polygon_uv(triangle_m: np.ndarray, u: np.ndarray, v: np.ndarray):
    """The (3, 3) triangle as a shapely polygon in its plane's (u, v) coordinates."""
    return shapely.Polygon((triangle_m - triangle_m[0]) @ np.stack([u, v], axis=1))


def triangulate_uv(part) -> np.ndarray | None:
    """(T, 3, 2) triangles of a shapely (multi)polygon (slivers of zero area dropped), None
    if GEOS cannot triangulate it."""
    try:
        triangles = shapely.get_parts(shapely.constrained_delaunay_triangles(part))
    except GEOSException:
        return None
    uv = shapely.get_coordinates(shapely.get_exterior_ring(triangles)).reshape(-1, 4, 2)[:, :3]
    e1, e2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    # Collinear points on a cut edge leave zero-area slivers: no face.
    return uv[np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]) > 2 * MIN_PIECE_M2 * 1e-4]


def replace_faces(mesh: LabelledMesh, cut: np.ndarray, piece_uv: list[np.ndarray],
                  piece_parent: list[int], flags: list[np.ndarray] | None = None
                  ) -> tuple[LabelledMesh, np.ndarray, np.ndarray | None]:
    """The mesh with the ``cut`` faces replaced by their pieces.

    Parameters
    ----------
    mesh
    cut : (F,) bool
        Faces that are replaced.
    piece_uv : list of (T_k, 3, 2) float
        Pieces of face ``piece_parent[k]`` in its plane coordinates (:func:`face_frames`).
    piece_parent : list of int
    flags : list of (T_k,) bool, optional
        A flag per piece, returned per output face (False for faces not cut).

    Returns
    -------
    mesh
        Faces not cut in their order, then the pieces, each turned like its parent.
    parent : (F',) int64
        Index of each output face's face in the input.
    flag : (F',) bool or None
    """
    normals, u, v, origin = face_frames(mesh)
    keep = np.flatnonzero(~cut)
    if not len(piece_uv):
        return mesh, np.arange(len(mesh.faces)), None if flags is None else np.zeros(
            len(mesh.faces), dtype=bool)
    parents = np.concatenate([np.full(len(p), k) for p, k in zip(piece_uv, piece_parent)])
    uv = np.concatenate(piece_uv)
    corners = (origin[parents, None, :] + uv[:, :, :1] * u[parents, None, :]
               + uv[:, :, 1:2] * v[parents, None, :])  # (T, 3, 3)
    turn = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    flip = np.einsum("ij,ij->i", turn, normals[parents]) < 0
    corners[flip] = corners[flip][:, ::-1]
    parent = np.concatenate([keep, parents]).astype(np.int64)
    vertices = np.concatenate([mesh.vertices_m, corners.reshape(-1, 3)])
    pieces = len(mesh.vertices_m) + np.arange(3 * len(corners)).reshape(-1, 3)
    faces = np.concatenate([mesh.faces[keep], pieces])
    out = LabelledMesh(vertices, faces, mesh.face_label[parent], mesh.face_facade[parent])
    flag = None
    if flags is not None:
        flag = np.concatenate([np.zeros(len(keep), dtype=bool), *flags])
    return out, parent, flag
