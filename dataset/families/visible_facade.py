"""Facade seen straight on: the part of each facade that no other surface hides from the front.

The full truth counts every square metre of a facade, also the wall and the
lower part of a balcony door behind a railing, or a strip under a roof's
overhang. A method that reads what it sees from outside cannot count those; the
*visible* truth is what it can: a point of a facade is visible when the ray from
it along the facade's outward normal meets no other surface of the building
(an orthographic view straight at the facade, the limit of its ideal view from
far away). Computed exactly, by polygons: for each plane of a facade (a curved
facade has one per facet, a recessed back wall or a recessed pane its own), every
other triangle of the mesh is clipped to the half-space in front of the plane
and projected onto it; the union of those shadows, intersected with the
facade's wall, window and door triangles, is their hidden area.
"""

from __future__ import annotations

from collections import defaultdict

import numpy as np
import shapely
from shapely.geometry import Polygon

from envelope.classes import FACADE_CLASSES, NO_FACADE
from envelope.mesh import LabelledMesh, plane_bases

IN_FRONT_TOL_M = 1e-6
"""A point this far or less in front of a facade plane lies on it (the mesh merges vertices
at 1 nm, and surfaces that touch a facade at an edge, like reveals, must not hide it)."""
PLANE_DECIMALS = 6  # facade triangles whose normal and offset agree to 1 µm share a plane
MIN_SHADOW_M2 = 1e-12  # a triangle seen edge-on from the plane projects to (almost) nothing


def hidden_facade_areas_m2(mesh: LabelledMesh) -> dict[int, dict[int, float]]:
    """Per facade id, per facade class (wall, window, door): area hidden from the front, m².

    mesh : the building's labelled mesh; facade triangles are those with a facade id
    (>= 1) and a facade class. Every class of every facade appears (0.0 when nothing
    hides it).
    """
    triangles = mesh.triangles_m
    normals = mesh.face_normals()
    is_facade = (mesh.face_facade != NO_FACADE) & np.isin(mesh.face_label, FACADE_CLASSES)
    planes: dict[tuple, list[int]] = defaultdict(list)
    offsets = np.einsum("ij,ij->i", normals, triangles[:, 0])
    keys = np.round(np.column_stack([normals, offsets]), PLANE_DECIMALS) + 0.0
    for i in np.flatnonzero(is_facade):
        planes[(int(mesh.face_facade[i]), *keys[i])].append(i)
    hidden = {int(f): {int(c): 0.0 for c in FACADE_CLASSES}
              for f in np.unique(mesh.face_facade[is_facade])}
    for key, members in planes.items():
        members = np.asarray(members)
        normal = normals[members].mean(axis=0)
        normal /= np.linalg.norm(normal)
        for label, area in _hidden_in_plane(triangles, members, mesh.face_label[members],
                                            normal).items():
            hidden[key[0]][label] += area
    return hidden


def _hidden_in_plane(triangles: np.ndarray, members: np.ndarray, labels: np.ndarray,
                     normal: np.ndarray) -> dict[int, float]:
    """Hidden area per class of the coplanar facade triangles ``members`` facing ``normal``."""
    u, v = (b[0] for b in plane_bases(normal[None, :]))
    basis = np.stack([u, v])
    own = triangles[members] @ basis.T  # (M, 3, 2)
    others = np.ones(len(triangles), dtype=bool)
    others[members] = False
    shadow = front_shadow(triangles, others, triangles[members[0], 0], normal, basis,
                          (*own.reshape(-1, 2).min(axis=0), *own.reshape(-1, 2).max(axis=0)))
    if shadow.is_empty:
        return {}
    out: dict[int, float] = {}
    for label in np.unique(labels):
        faces = shapely.union_all(shapely.polygons(own[labels == label]))
        out[int(label)] = float(faces.intersection(shadow).area)
    return out


def front_shadow(triangles_m: np.ndarray, occluders: np.ndarray, origin_m: np.ndarray,
                 normal: np.ndarray, basis: np.ndarray, bounds_uv: tuple[float, ...]):
    """What the ``occluders`` hide of a plane seen straight on from the front (shapely, m).

    triangles_m : (F, 3, 3) float, world metres. occluders : (F,) bool, the triangles that
    may hide the plane. origin_m : (3,) a point of the plane; normal : (3,) its outward unit
    normal; basis : (2, 3) orthonormal in-plane axes (the result's u, v). bounds_uv :
    (u_min, v_min, u_max, v_max) of the region of interest. The part of each occluder in
    front of the plane (more than :data:`IN_FRONT_TOL_M`) is projected along the normal;
    the union of those shadows is returned (empty when nothing is in front).
    """
    lo, hi = np.asarray(bounds_uv[:2]), np.asarray(bounds_uv[2:])
    depth = (triangles_m - origin_m) @ normal  # (F, 3): metres in front of the plane
    flat = triangles_m @ basis.T  # (F, 3, 2)
    edges = flat[:, 1:] - flat[:, :1]
    flat_area = 0.5 * np.abs(edges[:, 0, 0] * edges[:, 1, 1] - edges[:, 0, 1] * edges[:, 1, 0])
    # Faces edge-on to the plane (reveals, the sides of a slab) cast no shadow.
    candidates = occluders & (depth.max(axis=1) > IN_FRONT_TOL_M) & (flat_area > MIN_SHADOW_M2)
    candidates &= np.all(flat.max(axis=1) > lo, axis=1) & np.all(flat.min(axis=1) < hi, axis=1)
    whole = candidates & (depth.min(axis=1) > IN_FRONT_TOL_M)
    shadows = list(shapely.polygons(flat[whole]))
    for i in np.flatnonzero(candidates & ~whole):
        ring = _clip_in_front(triangles_m[i], depth[i])
        if len(ring) >= 3:
            shadows.append(Polygon(ring @ basis.T))
    return shapely.union_all(shadows) if shadows else Polygon()


def _clip_in_front(triangle: np.ndarray, depth: np.ndarray) -> np.ndarray:
    """(k, 3) polygon: the part of ``triangle`` ((3, 3)) whose depth ((3,)) is >= the tolerance."""
    keep = depth > IN_FRONT_TOL_M
    if keep.all():
        return triangle
    out = []
    for k in range(3):
        a, b, da, db = triangle[k], triangle[(k + 1) % 3], depth[k], depth[(k + 1) % 3]
        if keep[k]:
            out.append(a)
        if keep[k] != keep[(k + 1) % 3]:
            t = (IN_FRONT_TOL_M - da) / (db - da)
            out.append(a + t * (b - a))
    return np.asarray(out)
