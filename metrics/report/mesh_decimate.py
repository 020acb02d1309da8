"""Vertex-clustering decimation of a mesh with per-vertex class labels (for the report's viewer)."""

from __future__ import annotations

import numpy as np

CELL_GROWTH = 1.25  # each pass widens the grid cell by this factor until few enough faces remain


def decimate_vertex_clustering(
    vertices_m: np.ndarray, faces: np.ndarray, vertex_labels: np.ndarray, max_faces: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Merge the vertices in each cell of a cubic grid until at most ``max_faces`` faces remain.

    vertices_m : (V, 3) float, faces : (F, 3) int, vertex_labels : (V,) int.
    Returns (V', 3) cluster-mean vertices, (F', 3) faces without collapsed or
    repeated triangles, and (V',) labels (each cluster's most common label).
    A mesh already within ``max_faces`` is returned unchanged.

    Raises
    ------
    ValueError
        If ``max_faces`` is not positive.
    """
    if max_faces < 1:
        raise ValueError(f"max_faces must be positive, got {max_faces}")
    v = np.asarray(vertices_m, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    labels = np.asarray(vertex_labels, dtype=np.int64)
    if len(f) <= max_faces:
        return v, f, labels
    extent_m = float(np.ptp(v, axis=0).max()) or 1.0
    cell_m = extent_m / np.sqrt(max_faces)  # a surface of N cells has about 2N triangles
    while True:
        out = _cluster(v, f, labels, cell_m)
        if len(out[1]) <= max_faces:
            return out
        cell_m *= CELL_GROWTH


def _cluster(v: np.ndarray, f: np.ndarray, labels: np.ndarray, cell_m: float):
    keys = np.floor((v - v.min(axis=0)) / cell_m).astype(np.int64)
    _, cluster = np.unique(keys, axis=0, return_inverse=True)
    cluster = cluster.reshape(-1)
    n = int(cluster.max()) + 1
    counts = np.bincount(cluster, minlength=n)[:, None]
    centres = np.stack([np.bincount(cluster, v[:, d], minlength=n) for d in range(3)], 1) / counts
    # Most common label per cluster: count (cluster, label) pairs, keep each cluster's largest.
    pairs, votes = np.unique(cluster * 256 + labels, return_counts=True)
    order = np.lexsort((-votes, pairs // 256))
    first = np.unique(pairs[order] // 256, return_index=True)[1]
    cluster_labels = (pairs[order][first] % 256).astype(np.int64)
    g = cluster[f]
    g = g[(g[:, 0] != g[:, 1]) & (g[:, 1] != g[:, 2]) & (g[:, 0] != g[:, 2])]
    _, keep = np.unique(np.sort(g, axis=1), axis=0, return_index=True)
    return centres, g[np.sort(keep)], cluster_labels
