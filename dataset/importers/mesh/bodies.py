"""The bodies of an imported building mesh, each turned to face outwards.

A BIM export is many bodies, one or more per element: closed solids, solids with a hole
or a crack (IfcOpenShell cannot close every element), solids whose faces are wound
inconsistently or inside out, and single-face panels (curtain-wall glass). A *body* is a
set of faces joined across their edges (after merging coincident vertices, within one
element when elements are given): an edge that two faces use joins them, and round an edge
that more use (solids meeting there) each solid's two faces are paired
(:mod:`dataset.importers.mesh.edge_pairs`), so touching bodies stay apart and each stays closed.
:func:`orient_bodies` makes each body's winding consistent (trimesh's ``fix_winding``) and
turns it so that its signed volume is positive: outward normals for every closed body,
whatever the others do -- unless it is a cavity: a body whose faces point into a space
that the other bodies enclose (the room inside a merged shell of walls and slabs) keeps
its orientation. A flat body (a sheet) has no inside: its orientation is left to the
visibility test, which looks from both of its sides.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dataset.importers.mesh.edge_pairs import face_pairs
from envelope.geometry.raycast import INSIDE_WINDING, winding_numbers
from envelope.mesh import MERGE_DECIMALS

SHEET_RELATIVE_THICKNESS = 1e-6
"""A body thinner than this fraction of its size along its mean normal is flat: a sheet."""
CAVITY_PROBE_M = 1e-3
"""A negative body's inside is probed this far from its largest face, on its normal side."""


@dataclass(frozen=True)
class Bodies:
    """What :func:`orient_bodies` found.

    Attributes
    ----------
    faces : (F, 3) int64
        The input faces, each body's winding made consistent and outward.
    body : (F,) int64
        Body index of every face.
    open_body : (F,) bool
        Faces of bodies with an open edge (a hole, a crack, a single face).
    sheet : (F,) bool
        Faces of flat bodies (no inside, either side may face out).
    counts : dict
        ``bodies``, ``closed``, ``open``, ``sheets``, ``turned_inside_out`` (bodies turned
        because their volume was negative), ``cavities`` (negative bodies left as they are:
        the others enclose them), ``rewound`` (bodies whose faces were wound
        inconsistently).
    """

    faces: np.ndarray
    body: np.ndarray
    open_body: np.ndarray
    sheet: np.ndarray
    counts: dict[str, int]


def orient_bodies(vertices_m: np.ndarray, faces: np.ndarray,
                  group: np.ndarray | None = None) -> Bodies:
    """Find the bodies of a triangle mesh and turn each to face outwards.

    Parameters
    ----------
    vertices_m : (V, 3) float
        World metres.
    faces : (F, 3) int
        Triangles, any winding.
    group : (F,) int, optional
        Element of every face (an IFC product); a body never spans two elements.

    Returns
    -------
    Bodies
    """
    import trimesh

    v = np.asarray(vertices_m, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    g = np.zeros(len(f), dtype=np.int64) if group is None else np.asarray(group, np.int64)
    merged = _merge_within_groups(v, f, g)
    n_faces = len(f)
    adjacency = face_pairs(_merged_positions(v, f, merged), merged)
    components = trimesh.graph.connected_components(adjacency, nodes=np.arange(n_faces),
                                                    min_len=1)
    body = np.empty(n_faces, dtype=np.int64)
    for i, c in enumerate(sorted(components, key=lambda c: int(np.min(c)))):
        body[c] = i
    n_bodies = int(body.max(initial=-1)) + 1
    open_edges, unwound = _edge_defects(merged, body, n_bodies)
    out = f.copy()
    for b in np.flatnonzero(unwound):
        members = np.flatnonzero(body == b)
        sub = trimesh.Trimesh(v, f[members], process=False, validate=False)
        trimesh.repair.fix_winding(sub)
        out[members] = sub.faces
    tri = v[out]
    centre = np.zeros((n_bodies, 3))
    np.add.at(centre, body, tri.mean(axis=1))
    centre /= np.bincount(body, minlength=n_bodies)[:, None]
    rel = tri - centre[body][:, None, :]
    volume = np.bincount(body, weights=np.einsum("ij,ij->i", rel[:, 0],
                                                 np.cross(rel[:, 1], rel[:, 2])) / 6.0,
                         minlength=n_bodies)
    sheet_body = _flat(tri, body, n_bodies)
    negative = (volume < 0) & ~sheet_body
    cavity = _cavities(tri, body, np.flatnonzero(negative), n_bodies)
    turn = negative & ~cavity
    out[turn[body]] = out[turn[body]][:, ::-1]
    is_open = open_edges > 0
    counts = {"bodies": n_bodies, "closed": int((~is_open).sum()), "open": int(is_open.sum()),
              "sheets": int(sheet_body.sum()), "turned_inside_out": int(turn.sum()),
              "cavities": int(cavity.sum()), "rewound": int(unwound.sum())}
    return Bodies(out, body, is_open[body], sheet_body[body], counts)


def _cavities(tri: np.ndarray, body: np.ndarray, negative: np.ndarray, n_bodies: int
              ) -> np.ndarray:
    """(n_bodies,) bool: negative bodies whose inside (probed off their largest face, on its
    normal side) the other bodies enclose."""
    out = np.zeros(n_bodies, dtype=bool)
    if len(negative) == 0:
        return out
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area = np.linalg.norm(cross, axis=1)
    probes, own = [], []
    for b in negative:
        members = np.flatnonzero(body == b)
        f = members[np.argmax(area[members])]
        probes.append(tri[f].mean(axis=0) + CAVITY_PROBE_M * cross[f] / area[f])
        own.append(winding_numbers(tri[members], probes[-1][None])[0])
    others = winding_numbers(tri, np.asarray(probes)) - np.asarray(own)
    out[negative] = others >= INSIDE_WINDING
    return out


def _merge_within_groups(v: np.ndarray, f: np.ndarray, g: np.ndarray) -> np.ndarray:
    """(F, 3) faces over vertices merged to :data:`MERGE_DECIMALS` within each group."""
    if len(f) == 0:
        return f
    corner_group = np.repeat(g, 3)
    keys = np.concatenate([np.round(v[f.reshape(-1)], MERGE_DECIMALS) + 0.0,
                           corner_group[:, None].astype(np.float64)], axis=1)
    _, inverse = np.unique(keys, axis=0, return_inverse=True)
    return inverse.reshape(-1, 3)


def _merged_positions(v: np.ndarray, f: np.ndarray, merged: np.ndarray) -> np.ndarray:
    """(U, 3) a position for every merged vertex (one of the corners merged into it)."""
    out = np.zeros((merged.max(initial=-1) + 1, 3))
    out[merged.reshape(-1)] = v[f.reshape(-1)]
    return out


def _edge_defects(faces: np.ndarray, body: np.ndarray, n_bodies: int
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Per body: the number of edges used once (open), and whether an edge that two of its
    faces share is walked the same way by both (inconsistent winding)."""
    directed = faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
    edge_body = np.repeat(body, 3)
    forward = directed[:, 0] < directed[:, 1]
    key = np.concatenate([edge_body[:, None], np.sort(directed, axis=1)], axis=1)
    _, inverse, total = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    inverse = inverse.reshape(-1)
    net = np.bincount(inverse, weights=np.where(forward, 1, -1), minlength=len(total))
    owner = np.zeros(len(total), dtype=np.int64)
    owner[inverse] = edge_body
    open_edges = np.bincount(owner[total == 1], minlength=n_bodies)
    unwound = np.bincount(owner[(total == 2) & (net != 0)], minlength=n_bodies) > 0
    return open_edges, unwound


def _flat(tri: np.ndarray, body: np.ndarray, n_bodies: int) -> np.ndarray:
    """(n_bodies,) bool: bodies whose corners lie in one plane (to a relative tolerance)."""
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    # Orientation-free mean normal: the dominant direction of the area-weighted normals.
    outer = np.einsum("fi,fj->fij", cross, cross)
    moment = np.zeros((n_bodies, 3, 3))
    np.add.at(moment, body, outer)
    normal = np.linalg.eigh(moment)[1][:, :, -1]  # (B, 3) unit
    heights = np.einsum("fkd,fd->fk", tri, normal[body])
    lo = np.full(n_bodies, np.inf)
    hi = np.full(n_bodies, -np.inf)
    np.minimum.at(lo, body, heights.min(axis=1))
    np.maximum.at(hi, body, heights.max(axis=1))
    lo3 = np.full((n_bodies, 3), np.inf)
    hi3 = np.full((n_bodies, 3), -np.inf)
    np.minimum.at(lo3, body, tri.min(axis=1))
    np.maximum.at(hi3, body, tri.max(axis=1))
    span = np.linalg.norm(hi3 - lo3, axis=1)
    return (hi - lo) <= SHEET_RELATIVE_THICKNESS * np.maximum(span, 1e-12)
