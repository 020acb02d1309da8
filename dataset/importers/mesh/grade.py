"""Ground level of an imported building: cut its mesh at grade.

An exported building often reaches below the ground (foundation walls, a crawl space, a
basement). :func:`split_at_height` cuts every face that crosses the ground plane into
pieces wholly above or wholly below it, with one new vertex per cut edge, so the mesh stays
conforming and every body stays closed; the importer then counts only the pieces above.
"""

from __future__ import annotations

import numpy as np

from envelope.mesh import LabelledMesh


def split_at_height(mesh: LabelledMesh, z_m: float) -> tuple[LabelledMesh, np.ndarray]:
    """Cut the faces that cross the plane ``z = z_m`` into pieces on either side.

    Parameters
    ----------
    mesh
        Any triangle mesh; faces that do not cross the plane are kept as they are.
    z_m
        Height of the cutting plane, the mesh's frame.

    Returns
    -------
    mesh
        The same surface: uncut faces first in their order, then the pieces, each with its
        parent's label and facade id; each piece keeps its parent's orientation.
    parent : (F',) int64
        Index of each output face's face in the input.
    """
    v, f = mesh.vertices_m, mesh.faces
    side = np.sign(v[:, 2] - z_m).astype(np.int64)  # -1 below, 0 on, +1 above
    s = side[f]
    crossing = (s.min(axis=1) < 0) & (s.max(axis=1) > 0)
    keep = np.flatnonzero(~crossing)
    new_vertices: list[np.ndarray] = []
    cut_vertex: dict[tuple[int, int], int] = {}
    pieces: list[tuple[int, int, int]] = []
    parents: list[int] = []
    for i in np.flatnonzero(crossing):
        below: list[int] = []
        above: list[int] = []
        for k in range(3):
            p, q = int(f[i, k]), int(f[i, (k + 1) % 3])
            if side[p] <= 0:
                below.append(p)
            if side[p] >= 0:
                above.append(p)
            if side[p] * side[q] < 0:
                key = (min(p, q), max(p, q))
                if key not in cut_vertex:
                    a, b = v[key[0]], v[key[1]]
                    t = (z_m - a[2]) / (b[2] - a[2])
                    point = a + t * (b - a)
                    point[2] = z_m
                    cut_vertex[key] = len(v) + len(new_vertices)
                    new_vertices.append(point)
                below.append(cut_vertex[key])
                above.append(cut_vertex[key])
        for polygon in (below, above):
            for k in range(1, len(polygon) - 1):  # a triangle or a quad: a fan
                pieces.append((polygon[0], polygon[k], polygon[k + 1]))
                parents.append(int(i))
    parent = np.concatenate([keep, np.asarray(parents, dtype=np.int64)])
    vertices = np.concatenate([v, np.asarray(new_vertices).reshape(-1, 3)])
    faces = np.concatenate([f[keep], np.asarray(pieces, dtype=np.int64).reshape(-1, 3)])
    return LabelledMesh(vertices, faces, mesh.face_label[parent], mesh.face_facade[parent]), parent
