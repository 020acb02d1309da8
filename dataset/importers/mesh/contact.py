"""Cut the faces of a building's bodies where another body's face lies against them.

BIM solids touch: a wall butts against the side of another at a corner, a window lining
lies against its reveal. The part of a face covered by a touching body is inside the
building, the rest may be facade; the visibility test (:mod:`envelope.geometry.visibility`) decides
a
face as a whole, so :func:`split_touching_faces` cuts each face along the outline of the
opposite-facing coplanar faces that cover it -- and, where two overlapping solids are
flush on one side, along the earlier solid's coincident face, whose twin must not count
twice. The pieces are triangulated with shapely's constrained Delaunay triangulation;
nothing else changes.
"""

from __future__ import annotations

import numpy as np
import shapely
from shapely.errors import GEOSException

from dataset.importers.mesh.face_pieces import (
    MIN_PIECE_M2,
    face_frames,
    face_polygon_uv,
    replace_faces,
    triangulate_uv,
)
from envelope.mesh import LabelledMesh

PLANE_DECIMALS_NORMAL = 6  # faces whose unit normals agree to 1e-6 are parallel
PLANE_DECIMALS_OFFSET_M = 5  # ... and whose plane offsets agree to 10 um, coplanar
BOX_TOLERANCE_M = 1e-9  # bounding boxes that overlap by less than this do not touch


def split_touching_faces(
    mesh: LabelledMesh, which: np.ndarray
) -> tuple[LabelledMesh, np.ndarray, np.ndarray]:
    """Cut faces in ``which`` where coplanar faces of other bodies lie on them.

    Two kinds of cover: an *opposite* face (the faces touch: that part is inside the
    building, and the rays will find it hidden) and, for two overlapping solids flush on
    one side, an earlier face facing the *same* way (that part is the earlier face's
    twin and must not count twice).

    Parameters
    ----------
    mesh
        The building: faces of touching bodies, z up, metres.
    which : (F,) bool
        Faces to cut (the facades' candidates); any face may cover them.

    Returns
    -------
    mesh
        Faces not cut in their order, then the pieces of each cut face (its label, facade
        id and orientation).
    parent : (F',) int64
        Index of each output face's face in the input.
    twin : (F',) bool
        Pieces that an earlier same-facing face already covers.
    """
    normals, basis_u, basis_v, _ = face_frames(mesh)
    tri = mesh.triangles_m
    offsets = np.einsum("ij,ij->i", normals, tri[:, 0])
    lo, hi = tri.min(axis=1), tri.max(axis=1)
    extent = hi - lo  # a face flat along an axis overlaps along it whatever its bounds
    keys = np.concatenate([np.round(normals, PLANE_DECIMALS_NORMAL) + 0.0,
                           np.round(offsets, PLANE_DECIMALS_OFFSET_M)[:, None] + 0.0], axis=1)
    by_plane: dict[tuple[float, ...], list[int]] = {}
    for j, k in enumerate(map(tuple, keys)):
        by_plane.setdefault(k, []).append(j)

    def overlapping(faces: list[int] | None, i: int) -> np.ndarray:
        """Those of ``faces`` whose bounding boxes overlap face i's."""
        f = np.asarray(faces if faces else [], dtype=np.int64)
        near = np.all((lo[f] < hi[i] - BOX_TOLERANCE_M) & (hi[f] > lo[i] + BOX_TOLERANCE_M)
                      | (extent[f] < BOX_TOLERANCE_M) | (extent[i] < BOX_TOLERANCE_M), axis=1)
        return f[near]

    piece_uv: list[np.ndarray] = []
    piece_parent: list[int] = []
    piece_twin: list[np.ndarray] = []
    cut = np.zeros(len(tri), dtype=bool)
    for i in np.flatnonzero(which & (np.linalg.norm(normals, axis=1) > 0.5)):
        opposite = overlapping(by_plane.get(tuple(-keys[i] + 0.0)), i)
        same = overlapping(by_plane.get(tuple(keys[i])), i)
        same = same[same < i]
        if len(opposite) == 0 and len(same) == 0:
            continue
        parts = _cover_twin_rest(tri, i, opposite, same, basis_u[i], basis_v[i])
        if parts is None:
            continue  # GEOS could not cut it: the rays decide the face as a whole
        triangulated = [(triangulate_uv(part), is_twin) for part, is_twin in parts
                        if part.area >= MIN_PIECE_M2]
        if any(t is None for t, _ in triangulated):
            continue
        cut[i] = True
        for t, is_twin in triangulated:
            piece_uv.append(t)
            piece_parent.append(int(i))
            piece_twin.append(np.full(len(t), is_twin))
    if not cut.any():
        return mesh, np.arange(len(tri)), np.zeros(len(tri), dtype=bool)
    out, parent, twin = replace_faces(mesh, cut, piece_uv, piece_parent, piece_twin)
    return out, parent, twin


def _cover_twin_rest(tri: np.ndarray, i: int, opposite: np.ndarray, same: np.ndarray,
                     u: np.ndarray, v: np.ndarray):
    """Face i's parts in its plane coordinates: [(covered, False), (twin, True), (rest,
    False)], or None when there is nothing to cut or GEOS fails on the polygons."""
    own = face_polygon_uv(tri[i], u, v)
    origin, uv = tri[i, 0], np.stack([u, v], axis=1)
    try:
        cover = shapely.union_all(shapely.polygons((tri[opposite] - origin) @ uv)
                                  ).intersection(own)
        twin = shapely.union_all(shapely.polygons((tri[same] - origin) @ uv)
                                 ).intersection(own).difference(cover)
        rest = own.difference(cover).difference(twin)
    except GEOSException:
        return None
    if twin.area < MIN_PIECE_M2 and min(cover.area, rest.area) < MIN_PIECE_M2:
        return None  # not covered, or wholly covered by touching faces: the rays decide
    return [(cover, False), (twin, True), (rest, False)]
