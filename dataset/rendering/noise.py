"""Procedural noise of the RGB looks: smooth value noise, an integer hash and the fade of
features smaller than a pixel (a cheap mip-map). Pure functions of coordinates and a seed."""

from __future__ import annotations

import numpy as np


def value_noise(x: np.ndarray, y: np.ndarray, seed: int) -> np.ndarray:
    """Smooth 2-D value noise in [0, 1] with unit lattice spacing, same shape as ``x``."""
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = x - x0, y - y0
    fx, fy = fx * fx * (3 - 2 * fx), fy * fy * (3 - 2 * fy)
    ix, iy = x0.astype(np.int64), y0.astype(np.int64)
    c00, c10 = hash01(ix, iy, seed), hash01(ix + 1, iy, seed)
    c01, c11 = hash01(ix, iy + 1, seed), hash01(ix + 1, iy + 1, seed)
    return (c00 * (1 - fx) + c10 * fx) * (1 - fy) + (c01 * (1 - fx) + c11 * fx) * fy


def hash01(ix: np.ndarray, iy: np.ndarray, seed: int) -> np.ndarray:
    # Integer hash on int64 arrays (wrap-around is intended); uniform in [0, 1].
    h = ix * np.int64(374761393) + iy * np.int64(668265263) + np.int64(seed % 2**31) * 97
    h = (h ^ (h >> 13)) * np.int64(1274126177)
    h = h ^ (h >> 16)
    return (h & 0xFFFFFF).astype(np.float64) / float(0xFFFFFF)


def detail(footprint_m: np.ndarray, feature_m: float) -> np.ndarray:
    """Weight of a texture feature of size ``feature_m``: 1 while pixels resolve it, fading
    to 0 once a pixel's footprint reaches the feature size (a cheap mip-map)."""
    return np.clip(2.0 - 2.0 * footprint_m / feature_m, 0.0, 1.0)
