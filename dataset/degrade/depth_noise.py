"""LiDAR-like depth noise: range-dependent Gaussian, holes on glass, quantisation."""

from __future__ import annotations

import numpy as np

from envelope.classes import SemanticClass

SIGMA_PER_LEVEL = 0.01  # noise std as a fraction of the depth, per severity level
GLASS_HOLE_P_PER_LEVEL = 0.25  # probability that a window pixel has no depth, per level
QUANTUM_M_PER_LEVEL = 0.01  # quantisation step in metres, per level


def noisy_depth_m(
    depth_z_m: np.ndarray, labels: np.ndarray, level: float, rng: np.random.Generator
) -> np.ndarray:
    """(H, W) float32 z-depth with noise of severity ``level`` s (0 = none = a copy).

    Each measured pixel (depth > 0) gets N(0, (0.01 s z)^2) added; window pixels
    (``labels``, (H, W) class ids: glass) lose their depth with probability
    0.25 s; the result is rounded to multiples of 0.01 s metres and stays > 0
    where it was measured.
    """
    d = np.asarray(depth_z_m, dtype=np.float64)
    if level <= 0:
        return d.astype(np.float32)
    valid = d > 0
    noisy = d + rng.standard_normal(d.shape) * SIGMA_PER_LEVEL * level * d
    quantum = QUANTUM_M_PER_LEVEL * level
    noisy = np.maximum(np.round(noisy / quantum) * quantum, quantum)
    holes = (labels == SemanticClass.WINDOW) & (rng.random(d.shape) < min(
        1.0, GLASS_HOLE_P_PER_LEVEL * level))
    return np.where(valid & ~holes, noisy, 0.0).astype(np.float32)
