"""Cut faces along the lines where faces of other bodies pass through them.

Bodies of a BIM export overlap: a wall runs into another past their corner, a window frame
reaches into its wall, two boxes of one building interpenetrate. A face that passes into
another solid is partly inside the building; the visibility test decides a face as a
whole, so :func:`split_crossing_faces` cuts it along every segment where another face
crosses it (triangle-triangle intersection), and the rays then decide each piece.
Coplanar faces are :mod:`dataset.importers.mesh.contact`'s; faces that only touch a plane
(meeting along an edge, a partition butting against a wall) do not cut.
"""

from __future__ import annotations

import numpy as np
import shapely
from shapely.errors import GEOSException
from shapely.ops import polygonize, unary_union

from dataset.importers.mesh.face_pieces import (
    MIN_PIECE_M2,
    face_frames,
    face_polygon_uv,
    replace_faces,
    triangulate_uv,
)
from envelope.mesh import LabelledMesh

CROSSING_TOLERANCE_M = 1e-6
"""A face crosses a plane when corners lie more than this on both sides of it."""
MIN_SEGMENT_M = 1e-6
"""Cut segments shorter than this are ignored."""
SEGMENT_OVERSHOOT_M = 1e-5
"""Cut segments are lengthened by this at both ends, so that an end lying on the face's
edge (up to round-off) still reaches across it."""
BOX_PAD_M = 1e-6
"""Bounding boxes are padded by this before the pairs are searched."""


def split_crossing_faces(mesh: LabelledMesh, which: np.ndarray
                         ) -> tuple[LabelledMesh, np.ndarray]:
    """Cut the faces in ``which`` where other faces of the mesh pass through them.

    Parameters
    ----------
    mesh
        The building, z up, metres.
    which : (F,) bool
        Faces to cut (the facades' candidates); any face may cut them.

    Returns
    -------
    mesh
        Faces not cut in their order, then the pieces of each cut face (its label, facade
        id and orientation).
    parent : (F',) int64
        Index of each output face's face in the input.
    """
    normals, basis_u, basis_v, origin = face_frames(mesh)
    tri = mesh.triangles_m
    i, j = _crossing_pairs(tri, normals, np.asarray(which, dtype=bool))
    if len(i) == 0:
        return mesh, np.arange(len(tri))
    a, b = _plane_crossing_segments(tri[j], normals[i], origin[i])
    uv = np.stack([basis_u[i], basis_v[i]], axis=2)  # (P, 3, 2)
    a_uv = np.einsum("pd,pdk->pk", a - origin[i], uv)
    b_uv = np.einsum("pd,pdk->pk", b - origin[i], uv)
    keep = np.linalg.norm(b_uv - a_uv, axis=1) > MIN_SEGMENT_M
    i, a_uv, b_uv = i[keep], a_uv[keep], b_uv[keep]
    piece_uv: list[np.ndarray] = []
    piece_parent: list[int] = []
    cut = np.zeros(len(tri), dtype=bool)
    order = np.argsort(i, kind="stable")
    faces, starts = np.unique(i[order], return_index=True)
    for face, rows in zip(faces, np.split(order, starts[1:])):
        pieces = _pieces(face_polygon_uv(tri[face], basis_u[face], basis_v[face]),
                         a_uv[rows], b_uv[rows])
        if pieces is None:
            continue
        cut[face] = True
        piece_uv.extend(pieces)
        piece_parent.extend([int(face)] * len(pieces))
    out, parent, _ = replace_faces(mesh, cut, piece_uv, piece_parent)
    return out, parent


def _crossing_pairs(tri: np.ndarray, normals: np.ndarray, which: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray]:
    """(P,) face i in ``which`` and (P,) face j != i whose triangles cross each other's
    planes (corners strictly on both sides of each)."""
    lo, hi = tri.min(axis=1) - BOX_PAD_M, tri.max(axis=1) + BOX_PAD_M
    boxes = shapely.box(lo[:, 0], lo[:, 1], hi[:, 0], hi[:, 1])
    candidates = np.flatnonzero(which & (np.linalg.norm(normals, axis=1) > 0.5))
    if len(candidates) == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    q, j = shapely.STRtree(boxes).query(boxes[candidates], predicate="intersects")
    i = candidates[q]
    ok = (i != j) & (lo[j, 2] <= hi[i, 2]) & (hi[j, 2] >= lo[i, 2])
    ok &= np.linalg.norm(normals[j], axis=1) > 0.5
    i, j = i[ok], j[ok]
    d_j = np.einsum("pkd,pd->pk", tri[j] - tri[i][:, :1], normals[i])  # j's corners vs i's plane
    d_i = np.einsum("pkd,pd->pk", tri[i] - tri[j][:, :1], normals[j])
    t = CROSSING_TOLERANCE_M
    crossing = ((d_j.min(axis=1) < -t) & (d_j.max(axis=1) > t)
                & (d_i.min(axis=1) < -t) & (d_i.max(axis=1) > t))
    return i[crossing], j[crossing]


def _plane_crossing_segments(tri_j: np.ndarray, normal_i: np.ndarray, point_i: np.ndarray
                             ) -> tuple[np.ndarray, np.ndarray]:
    """(P, 3) and (P, 3): the ends of the segment where each triangle j crosses plane i."""
    d = np.einsum("pkd,pd->pk", tri_j - point_i[:, None, :], normal_i)  # (P, 3)
    ends = []
    for k in range(3):
        p, q = tri_j[:, k], tri_j[:, (k + 1) % 3]
        dp, dq = d[:, k], d[:, (k + 1) % 3]
        crosses = dp * dq < 0
        s = np.where(crosses, dp / np.where(crosses, dp - dq, 1.0), 0.0)
        ends.append((p + s[:, None] * (q - p), crosses))
        ends.append((p, np.abs(dp) <= CROSSING_TOLERANCE_M))
    points = np.stack([e[0] for e in ends], axis=1)  # (P, 6, 3)
    valid = np.stack([e[1] for e in ends], axis=1)  # (P, 6)
    # The two valid points furthest apart are the segment's ends.
    gap = np.linalg.norm(points[:, :, None, :] - points[:, None, :, :], axis=3)
    gap[~(valid[:, :, None] & valid[:, None, :])] = -1.0
    best = gap.reshape(len(points), -1).argmax(axis=1)
    rows = np.arange(len(points))
    return points[rows, best // 6], points[rows, best % 6]


def _pieces(own, a_uv: np.ndarray, b_uv: np.ndarray) -> list[np.ndarray] | None:
    """Triangulated pieces (each (T, 3, 2)) of the face polygon ``own`` cut along the
    segments (S, 2) ``a_uv`` -> ``b_uv``; None when they do not cut it or GEOS fails."""
    # Each segment is lengthened a little so that an end on the face's edge crosses it.
    direction = b_uv - a_uv
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    a_uv, b_uv = a_uv - SEGMENT_OVERSHOOT_M * direction, b_uv + SEGMENT_OVERSHOOT_M * direction
    try:
        lines = shapely.linestrings(np.stack([a_uv, b_uv], axis=1))
        if not shapely.intersects(lines, own).any():
            return None
        regions = [p for p in polygonize(unary_union([own.exterior, *lines.tolist()]))
                   if p.area >= MIN_PIECE_M2 and own.contains(p.representative_point())]
    except GEOSException:
        return None
    if len(regions) < 2:
        return None
    pieces = [triangulate_uv(r) for r in regions]
    return None if any(p is None for p in pieces) else pieces
