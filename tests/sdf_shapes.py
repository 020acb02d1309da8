"""Analytic signed distance functions and class labels for the neural3d meshing tests.

Not a test module: shapes shared by test_meshing, test_measure, test_footprint_sdf
and test_extract. All take (N, 3) world metres and return (N,) metres, positive outside.
"""

from __future__ import annotations

import numpy as np

from envelope.classes import SemanticClass


def box_sdf(points_m: np.ndarray, box_min_m, box_max_m) -> np.ndarray:
    """Exact SDF of an axis-aligned box."""
    lo, hi = np.asarray(box_min_m, float), np.asarray(box_max_m, float)
    q = np.abs(points_m - (lo + hi) / 2) - (hi - lo) / 2
    return np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(q.max(axis=1), 0.0)


def cylinder_sdf(points_m: np.ndarray, centre_xy_m, radius_m: float, z0_m: float, z1_m: float):
    """Exact SDF of a vertical capped cylinder."""
    radial = np.linalg.norm(points_m[:, :2] - np.asarray(centre_xy_m, float), axis=1) - radius_m
    vertical = np.maximum(z0_m - points_m[:, 2], points_m[:, 2] - z1_m)
    d = np.stack([radial, vertical], axis=1)
    return np.linalg.norm(np.maximum(d, 0.0), axis=1) + np.minimum(d.max(axis=1), 0.0)


def l_prism_sdf(points_m: np.ndarray) -> np.ndarray:
    """L-shaped prism 8 m tall: [0, 10] x [0, 4] joined with [0, 4] x [0, 12] (72 m²)."""
    return np.minimum(box_sdf(points_m, [0, 0, 0], [10, 4, 8]),
                      box_sdf(points_m, [0, 0, 0], [4, 12, 8]))


def banded_labels(sdf_fn, band_z_m: tuple[float, float]):
    """Label function: roof on top, background underneath, window in a height band, wall elsewhere.

    The side of the surface a point is on comes from the SDF's central-difference gradient.
    """

    def label(points_m: np.ndarray) -> np.ndarray:
        step = 1e-4
        gz = (sdf_fn(points_m + [0, 0, step]) - sdf_fn(points_m - [0, 0, step])) / (2 * step)
        gx = (sdf_fn(points_m + [step, 0, 0]) - sdf_fn(points_m - [step, 0, 0])) / (2 * step)
        gy = (sdf_fn(points_m + [0, step, 0]) - sdf_fn(points_m - [0, step, 0])) / (2 * step)
        nz = gz / np.maximum(np.sqrt(gx**2 + gy**2 + gz**2), 1e-12)
        out = np.full(len(points_m), int(SemanticClass.WALL))
        band = (points_m[:, 2] > band_z_m[0]) & (points_m[:, 2] < band_z_m[1])
        out[band] = SemanticClass.WINDOW
        out[nz > 0.7] = SemanticClass.ROOF
        out[nz < -0.7] = SemanticClass.BACKGROUND
        return out

    return label


def truth_mesh_of(tm, *, curved: bool = False):
    """LabelledMesh of a trimesh prism: side faces get facade ids by normal direction, from 1.

    Faces facing up are roof, down background, both facade 0; sides are wall. Side faces
    with the same azimuth (to 1 degree) share an id; ``curved=True`` gives every side face id 1.
    """
    from envelope.mesh import LabelledMesh

    n = tm.face_normals
    label = np.full(len(n), int(SemanticClass.WALL), dtype=np.uint8)
    label[n[:, 2] > 0.7] = SemanticClass.ROOF
    label[n[:, 2] < -0.7] = SemanticClass.BACKGROUND
    side = np.abs(n[:, 2]) <= 0.7
    azimuth = np.round(np.degrees(np.arctan2(n[:, 1], n[:, 0])) % 360).astype(int)
    ids = {a: i + 1 for i, a in enumerate(sorted(set(azimuth[side].tolist())))}
    facade = np.array([ids[a] if s else 0 for a, s in zip(azimuth, side)], dtype=np.int32)
    if curved:
        facade = side.astype(np.int32)
    return LabelledMesh(np.asarray(tm.vertices), np.asarray(tm.faces), label, facade)
