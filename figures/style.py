"""Shared look of the figures: class colours and image encodings for display."""

from __future__ import annotations

import numpy as np

from envelope.classes import CLASS_RGB, NUM_CLASSES, UNKNOWN_CLASS_RGB

CLASS_RGB_ARRAY = np.array(CLASS_RGB, dtype=np.uint8)  # (NUM_CLASSES, 3)


class MissingInput(ValueError):
    """A figure's input is not there (yet); the figure is skipped with this message."""


def colour_labels(labels: np.ndarray) -> np.ndarray:
    """(H, W) class ids -> (H, W, 3) uint8 colours (:data:`envelope.classes.CLASS_RGB`)."""
    palette = np.tile(np.array(UNKNOWN_CLASS_RGB, dtype=np.uint8), (256, 1))
    palette[:NUM_CLASSES] = CLASS_RGB
    return palette[np.asarray(labels, dtype=np.uint8)]


def colour_normals(normals_world: np.ndarray) -> np.ndarray:
    """(H, W, 3) unit normals -> (H, W, 3) uint8 as (n + 1) / 2; no surface (zero) is black."""
    n = np.asarray(normals_world, dtype=np.float64)
    rgb = np.round((np.clip(n, -1, 1) + 1) / 2 * 255).astype(np.uint8)
    rgb[(n == 0).all(axis=-1)] = 0
    return rgb


def colour_depth(depth_z_m: np.ndarray) -> np.ndarray:
    """(H, W) z-depth (0 = none) -> (H, W, 3) uint8, near bright, far dark, none white."""
    from matplotlib import colormaps

    d = np.asarray(depth_z_m, dtype=np.float64)
    hit = d > 0
    rgb = np.full(d.shape + (3,), 255, dtype=np.uint8)
    if hit.any():
        lo, hi = np.percentile(d[hit], [1, 99])
        t = np.clip((d - lo) / max(hi - lo, 1e-9), 0, 1)
        rgb[hit] = (colormaps["magma"](1 - 0.85 * t[hit])[:, :3] * 255).astype(np.uint8)
    return rgb
