"""Semantic-mask noise of a segmentation network: eroded, missed, false and bled windows.

Every function takes and returns an (H, W) uint8 class-id image (a new array;
the input is not modified) and acts on the window and wall classes only.
"""

from __future__ import annotations

import cv2
import numpy as np

from envelope.classes import SemanticClass

WINDOW = int(SemanticClass.WINDOW)
WALL = int(SemanticClass.WALL)
_FALSE_WINDOW_TRIES = 20


def erode_windows(labels: np.ndarray, k_px: int) -> np.ndarray:
    """Window regions eroded by ``k_px`` (square (2k+1)^2 kernel); lost pixels become wall.

    A w x h window rectangle surrounded by wall keeps (w - 2k)(h - 2k) pixels.
    """
    out = labels.copy()
    if k_px <= 0:
        return out
    window = (labels == WINDOW).astype(np.uint8)
    kept = cv2.erode(window, np.ones((2 * k_px + 1,) * 2, np.uint8),
                     borderType=cv2.BORDER_REPLICATE)
    out[(window == 1) & (kept == 0)] = WALL
    return out


def dilate_windows(labels: np.ndarray, k_px: int) -> np.ndarray:
    """Window regions grown by ``k_px`` into wall pixels (other classes keep their label)."""
    out = labels.copy()
    if k_px <= 0:
        return out
    window = (labels == WINDOW).astype(np.uint8)
    grown = cv2.dilate(window, np.ones((2 * k_px + 1,) * 2, np.uint8))
    out[(grown == 1) & (labels == WALL)] = WINDOW
    return out


def miss_windows(labels: np.ndarray, p: float, rng: np.random.Generator) -> np.ndarray:
    """Each window (4-connected region) relabelled wall with probability ``p``."""
    out = labels.copy()
    n, comp = cv2.connectedComponents((labels == WINDOW).astype(np.uint8), connectivity=4)
    if p <= 0 or n <= 1:
        return out
    missed = np.flatnonzero(rng.random(n - 1) < p) + 1
    out[np.isin(comp, missed)] = WALL
    return out


def false_windows(labels: np.ndarray, p: float, rng: np.random.Generator) -> np.ndarray:
    """For each window, with probability ``p``, its bounding box pasted as window onto a
    random spot of plain wall (a spot whose box is all wall; skipped if none is found)."""
    out = labels.copy()
    if p <= 0:
        return out
    n, _, stats, _ = cv2.connectedComponentsWithStats((labels == WINDOW).astype(np.uint8),
                                                      connectivity=4)
    h, w = labels.shape
    for i in np.flatnonzero(rng.random(n - 1) < p) + 1:
        bw, bh = int(stats[i, cv2.CC_STAT_WIDTH]), int(stats[i, cv2.CC_STAT_HEIGHT])
        if bw >= w or bh >= h:
            continue
        for _ in range(_FALSE_WINDOW_TRIES):
            x, y = int(rng.integers(0, w - bw + 1)), int(rng.integers(0, h - bh + 1))
            if (out[y : y + bh, x : x + bw] == WALL).all():
                out[y : y + bh, x : x + bw] = WINDOW
                break
    return out


def bleed_labels(labels: np.ndarray, k_px: int, rng: np.random.Generator) -> np.ndarray:
    """Pixels within ``k_px`` of a window/wall edge take the label of a random pixel at most
    ``k_px`` away along each axis (frames smeared into the wall and back)."""
    out = labels.copy()
    if k_px <= 0:
        return out
    kernel = np.ones((2 * k_px + 1,) * 2, np.uint8)
    near_window = cv2.dilate((labels == WINDOW).astype(np.uint8), kernel)
    near_wall = cv2.dilate((labels == WALL).astype(np.uint8), kernel)
    band = (near_window & near_wall).astype(bool) & np.isin(labels, (WINDOW, WALL))
    ys, xs = np.nonzero(band)
    h, w = labels.shape
    dy = rng.integers(-k_px, k_px + 1, len(ys))
    dx = rng.integers(-k_px, k_px + 1, len(xs))
    src = labels[np.clip(ys + dy, 0, h - 1), np.clip(xs + dx, 0, w - 1)]
    out[ys, xs] = np.where(np.isin(src, (WINDOW, WALL)), src, labels[ys, xs])
    return out


def mask_noise(labels: np.ndarray, level: float, rng: np.random.Generator) -> np.ndarray:
    """All mask noises at one level s: erode ``int(s)`` px, miss ``0.1 s``, false ``0.05 s``,
    bleed ``int(s)`` px (in that order)."""
    if level <= 0:
        return labels.copy()
    out = erode_windows(labels, int(level))
    out = miss_windows(out, min(1.0, 0.1 * level), rng)
    out = false_windows(out, min(1.0, 0.05 * level), rng)
    return bleed_labels(out, int(level), rng)
