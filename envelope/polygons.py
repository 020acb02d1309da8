"""Plane polygons given by their corners: the shoelace area of a 2D ring and Newell's normal
of a 3D one (each written once; the footprints as shapely polygons are
:mod:`envelope.footprint`).

A ring is its corners in order, the first not repeated at the end.
"""

from __future__ import annotations

import numpy as np


def polygon_area(corners_xy: np.ndarray) -> float:
    """Area of a simple polygon, (n, 2) corners in any unit (the area is in its square), by
    the shoelace formula: ``0.5 |x . roll(y, -1) - y . roll(x, -1)|``, either orientation."""
    c = np.asarray(corners_xy, dtype=np.float64)
    if c.ndim != 2 or c.shape[1] != 2:
        raise ValueError(f"corners must be (n, 2), got {c.shape}")
    x, y = c[:, 0], c[:, 1]
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


def newell_vector(ring: np.ndarray) -> np.ndarray:
    """(3,) Newell vector of an (n, 3) ring: length twice its (vector) area, direction by the
    right-hand rule (counter-clockwise seen from where it points); exact for a planar ring
    and the best-fit plane's normal for a nearly planar one."""
    p = np.asarray(ring, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"ring must be (n, 3), got {p.shape}")
    q = np.roll(p, -1, axis=0)
    return np.array([np.sum((p[:, 1] - q[:, 1]) * (p[:, 2] + q[:, 2])),
                     np.sum((p[:, 2] - q[:, 2]) * (p[:, 0] + q[:, 0])),
                     np.sum((p[:, 0] - q[:, 0]) * (p[:, 1] + q[:, 1]))])


def newell_normal(ring: np.ndarray) -> np.ndarray:
    """(3,) unit normal of an (n, 3) ring (:func:`newell_vector` normalised).

    Raises
    ------
    ValueError
        If the corners are on one line (no area).
    """
    n = newell_vector(ring)
    length = float(np.linalg.norm(n))
    if length == 0:
        raise ValueError("an outline has no area (its corners are on one line)")
    return n / length
