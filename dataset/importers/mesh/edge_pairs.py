"""Which faces of a triangle soup are joined across each edge, for finding its bodies.

An edge that two faces use joins them. An edge that more faces use is where bodies meet
(two walls butting at a mitred corner, a slab's edge on a wall's edge, four boxes round a
column): each body that reaches the edge fills a wedge round it, bounded by two of its
faces, and :func:`face_pairs` joins exactly those two -- the *radial* pairing of solid
modelling. Round the edge's direction ``d`` (from its lower to its higher vertex index), a
face that walks the edge along ``d`` has its normal towards increasing angle, one that
walks it against ``d`` towards decreasing angle; so a wedge that is inside runs from a face
walking against ``d`` to the next face, by angle, walking along it. Coincident faces (the
two faces of a mitre joint; the duplicated faces of two overlapping solids) share one
angle: a wedge opens at the faces of one angle that walk against ``d`` and closes at
those of the next angle that walk along it, matched one to one (duplicates are
interchangeable). An edge at which some wedge does not close so (a body inside out against
another, faces wound inconsistently) joins none of its faces: each body is open there, as
it would be with only edges of two faces joining.
"""

from __future__ import annotations

import numpy as np

TIE_RAD = 1e-6
"""Faces round an edge whose angles differ by less than this are coincident (a corner
rounded to 1 nm moves a face 1 cm wide by 1e-7 rad)."""


def face_pairs(vertices_m: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(P, 2) int64: pairs of faces joined across a shared edge.

    Parameters
    ----------
    vertices_m : (V, 3) float
        World metres.
    faces : (F, 3) int
        Triangles over merged vertices (a shared edge has the same two indices).

    Returns
    -------
    Face index pairs: the two faces of every edge that exactly two faces use (whatever
    their winding), and the radially paired faces (module docstring) of every edge that
    more use.
    """
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    if len(f) == 0:
        return np.zeros((0, 2), dtype=np.int64)
    start = f.reshape(-1)
    end = f[:, [1, 2, 0]].reshape(-1)
    apex = f[:, [2, 0, 1]].reshape(-1)
    face = np.repeat(np.arange(len(f)), 3)
    lo, hi = np.minimum(start, end), np.maximum(start, end)
    _, edge, count = np.unique(np.stack([lo, hi], axis=1), axis=0, return_inverse=True,
                               return_counts=True)
    edge = edge.reshape(-1)
    order = np.argsort(edge, kind="stable")
    manifold = order[count[edge[order]] == 2].reshape(-1, 2)
    pairs = [face[manifold]]
    many = np.flatnonzero(count[edge] > 2)
    if len(many):
        pairs.append(_radial_pairs(np.asarray(vertices_m, dtype=np.float64), lo[many],
                                   hi[many], apex[many], start[many] < end[many],
                                   edge[many], face[many]))
    return np.concatenate(pairs)


def _radial_pairs(v: np.ndarray, lo: np.ndarray, hi: np.ndarray, apex: np.ndarray,
                  along: np.ndarray, edge: np.ndarray, face: np.ndarray) -> np.ndarray:
    """(P, 2) faces paired round edges that three or more faces use; every argument is per
    use of an edge by a face, (N,): the edge's lower and higher vertex, the face's third
    vertex, whether the face walks lower -> higher, the edge's id and the face."""
    order = np.argsort(edge, kind="stable")
    lo, hi, apex, along, edge, face = (a[order] for a in (lo, hi, apex, along, edge, face))
    first = np.r_[True, edge[1:] != edge[:-1]]
    group = np.cumsum(first) - 1
    starts = np.flatnonzero(first)
    d = _unit(v[hi] - v[lo])
    w = v[apex] - v[lo]
    w -= np.einsum("ij,ij->i", w, d)[:, None] * d  # the face's direction off the edge
    # Angle 0: the face that reaches furthest off the edge (a sliver gives no direction).
    reach = np.linalg.norm(w, axis=1)
    widest = np.lexsort((-reach, group))[starts]
    e1 = _unit(w[widest][group])
    e2 = np.cross(d, e1)  # (e1, e2, d) right-handed: angle increases round d
    angle = np.mod(np.arctan2(np.einsum("ij,ij->i", w, e2), np.einsum("ij,ij->i", w, e1)),
                   2 * np.pi)
    angle[angle > 2 * np.pi - TIE_RAD] -= 2 * np.pi  # just below angle 0: with it
    by_angle = np.lexsort((angle, group))
    gap = np.diff(angle[by_angle]) > TIE_RAD
    new_cluster = np.r_[True, gap | (group[by_angle][1:] != group[by_angle][:-1])]
    cluster = np.empty(len(angle), dtype=np.int64)
    cluster[by_angle] = np.cumsum(new_cluster) - 1  # coincident faces: one angle
    cluster_group = group[by_angle][new_cluster]
    # The cluster after each round its edge (cyclic).
    following = np.arange(1, len(cluster_group) + 1)
    last = np.r_[cluster_group[1:] != cluster_group[:-1], True]
    following[last] = np.flatnonzero(np.r_[True, cluster_group[1:] != cluster_group[:-1]])
    n = len(cluster_group)
    n_along = np.bincount(cluster, weights=along, minlength=n).astype(np.int64)
    n_against = np.bincount(cluster, weights=~along, minlength=n).astype(np.int64)
    # A wedge opens at a cluster's faces walking against d and closes at the next
    # cluster's faces walking along it; an edge pairs only if every wedge does.
    ok = n_against == n_along[following]
    complete = np.bincount(cluster_group, weights=~ok) == 0
    use = complete[group]
    # Match the k-th opening face of a cluster with the k-th closing face of the next
    # (coincident duplicates are interchangeable).
    key = np.where(along, cluster, following[cluster])
    order = np.lexsort((face, key, along))
    order = order[use[order]]
    opening, closing = np.split(order, [int((~along[order]).sum())])
    return np.stack([face[opening], face[closing]], axis=1)


def _unit(x: np.ndarray) -> np.ndarray:
    """(N, 3) rows scaled to length 1 (zero rows stay zero)."""
    length = np.linalg.norm(x, axis=1, keepdims=True)
    return np.divide(x, length, out=np.zeros_like(x), where=length > 0)
