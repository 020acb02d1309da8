"""Check a user's mesh for impossible coordinates and likely wrong units, with their own messages.

Called by :func:`dataset.importers.mesh.mesh_files.read_labelled_mesh_file` on every mesh read,
before anything is derived from it, so that a NaN vertex or a file in millimetres
is reported as such rather than as "no facade found". Touching or overlapping
bodies are valid input and are not checked here.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

MAX_BUILDING_SIZE_M = 2000.0
"""A building's longest bounding-box side above this is absurd (the tallest is 828 m)."""
MIN_BUILDING_SIZE_M = 1.0
"""A building's longest bounding-box side below this is absurd (a kennel is a building)."""


def check_mesh_coordinates(vertices_m: np.ndarray, faces: np.ndarray, path: str | Path) -> None:
    """Raise ``ValueError`` for NaN/inf coordinates or an extent outside 1 m .. 2 km.

    Parameters
    ----------
    vertices_m : (V, 3) float
        The file's vertices, meant to be metres.
    faces : (F, 3) int
        Triangles; the extent is taken over the vertices they use.
    """
    v = np.asarray(vertices_m, dtype=np.float64).reshape(-1, 3)
    bad = ~np.isfinite(v).all(axis=1)
    if bad.any():
        raise ValueError(
            f"{path}: {int(bad.sum())} of {len(v)} vertices have NaN or infinite coordinates "
            f"(the first is vertex {int(np.flatnonzero(bad)[0])}); fix or delete them in the "
            "authoring tool and export again")
    f = np.asarray(faces, dtype=np.int64).reshape(-1)
    used = v[f] if len(f) else v
    if len(used) == 0:
        return
    size_m = float((used.max(axis=0) - used.min(axis=0)).max())
    if size_m > MAX_BUILDING_SIZE_M:
        if MIN_BUILDING_SIZE_M <= size_m / 1000 <= MAX_BUILDING_SIZE_M:
            raise ValueError(
                f"{path}: the building is {size_m:,.0f} units across, which as metres is larger "
                f"than {MAX_BUILDING_SIZE_M / 1000:.0f} km; the file is likely in millimetres "
                f"({size_m / 1000:.1f} m). Export it in metres (or scale it by 0.001)")
        raise ValueError(
            f"{path}: the building is {size_m:.3g} m across, larger than "
            f"{MAX_BUILDING_SIZE_M / 1000:.0f} km; check the file's units and scale (the mesh "
            "must be in metres)")
    if size_m < MIN_BUILDING_SIZE_M:
        raise ValueError(
            f"{path}: the building is only {size_m:.3g} m across, smaller than "
            f"{MIN_BUILDING_SIZE_M:.0f} m; check the file's units and scale (the mesh must be "
            "in metres; a file in kilometres needs scaling by 1000)")
