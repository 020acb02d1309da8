"""A triangle's facade area shared among wall, window and door by class probabilities.

The vertex-label rule (:func:`neural3d.extraction.facade_groups.class_area_m2`) gives a
triangle's area to the classes of its corners' argmax labels. A semantic field
that cannot follow an opening's edge to better than its grid cell (about 0.2 m
on a 45 m tower) blurs the window's indicator; the argmax of a blurred
rectangle is a rectangle with rounded corners, smaller than the opening (a
skyscraper's window area came out 3-6 % low), while the blurred indicator
itself still integrates to the opening's area. So the facade part of each
triangle (how much of it is wall, window or door at all, from the labels, as
before) is split among the facade classes by the mean over its corners of the
head's probabilities, renormalised over the facade classes: gross facade area
and everything that depends on which triangles are facade are unchanged.
"""

from __future__ import annotations

import numpy as np

from envelope.classes import FACADE_CLASSES, NUM_CLASSES


def split_facade_area_by_probability(
    shares_m2: np.ndarray, faces: np.ndarray, vertex_probabilities: np.ndarray
) -> np.ndarray:
    """Each triangle's facade area re-split among the facade classes by its corners' probabilities.

    Parameters
    ----------
    shares_m2 : (F, NUM_CLASSES) each triangle's area shared among classes by its
        corners' labels (m²)
    faces : (F, 3) int vertex indices
    vertex_probabilities : (V, NUM_CLASSES) class probabilities (>= 0) of every vertex,
        in :mod:`envelope.classes` id order

    Returns
    -------
    (F, NUM_CLASSES) m²: non-facade columns as given; the facade columns hold
    the triangle's facade area times the mean over its corners of
    p(class) / p(wall or window or door). A corner with no facade probability
    at all leaves its triangle's split as the labels gave it.
    """
    shares = np.asarray(shares_m2, dtype=np.float64)
    prob = np.asarray(vertex_probabilities, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    if shares.ndim != 2 or shares.shape[1] != NUM_CLASSES or faces.shape != (len(shares), 3):
        raise ValueError(f"need shares_m2 (F, {NUM_CLASSES}) and faces (F, 3), got "
                         f"{shares.shape} and {faces.shape}")
    if prob.ndim != 2 or prob.shape[1] != NUM_CLASSES or (len(faces) and faces.max() >= len(prob)):
        raise ValueError(f"vertex_probabilities must have shape (V, {NUM_CLASSES}) with a row "
                         f"for every vertex the faces index, got {prob.shape}")
    if len(prob) and (not np.isfinite(prob).all() or prob.min() < 0):
        raise ValueError("vertex_probabilities must be finite and >= 0")
    facade = list(FACADE_CLASSES)
    p = prob[:, facade]
    total = p.sum(axis=1, keepdims=True)
    p = p / np.where(total > 0, total, 1.0)
    split = p[faces].mean(axis=1)  # (F, 3), rows sum to 1 where every corner has some
    defined = (total[faces, 0] > 0).all(axis=1)
    out = shares.copy()
    facade_area = shares[:, facade].sum(axis=1)
    out[np.ix_(defined, facade)] = facade_area[defined, None] * split[defined]
    return out
