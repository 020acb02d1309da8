"""Field evaluations in chunks: how many points one call takes at most, defined once.

Marching cubes, vertex labels and colours, footprint planes, the trained
field's forward passes and the occupancy grid's refresh all evaluate at most
:data:`DEFAULT_CHUNK_POINTS` points per call unless told otherwise
(``ExtractConfig.chunk_points``), which bounds memory.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

DEFAULT_CHUNK_POINTS = 1 << 16  # 65k points: ~0.8 MB of float32 coordinates per call


def evaluate_in_chunks(
    fn: Callable[[np.ndarray], np.ndarray],
    points: np.ndarray,
    chunk_points: int,
    out_shape: tuple[int, ...] = (),
) -> np.ndarray:
    """``fn`` on ``points`` (N, D), at most ``chunk_points`` rows per call; (N, *out_shape)."""
    if chunk_points < 1:
        raise ValueError(f"chunk_points must be >= 1, got {chunk_points}")
    parts = []
    for start in range(0, len(points), chunk_points):
        chunk = points[start:start + chunk_points]
        out = np.asarray(fn(chunk))
        if out.shape != (len(chunk), *out_shape):
            raise ValueError(f"the callable returned shape {out.shape} for {len(chunk)} points; "
                             f"expected {(len(chunk), *out_shape)}")
        parts.append(out)
    if not parts:
        return np.zeros((0, *out_shape))
    return np.concatenate(parts)
