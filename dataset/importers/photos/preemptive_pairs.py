"""Which pairs of photos structure from motion matches in full: preemptive matching (Wu,
"Towards linear-time incremental structure from motion", 3DV 2013, as in VisualSFM).

Every pair is first matched on a few of each photo's features only, those of largest scale
(the ones most likely to be seen again from another distance), which is cheap; only pairs
with enough of these preliminary matches are matched in full and geometrically verified.
Nothing here reads the photos' names or their order: the pairs chosen depend on the
features alone, so an unordered folder (a user's) gets the same pairs in any order.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class PreemptiveMatching:
    """Match in full only the pairs whose ``top_features`` largest-scale features give
    ``min_matches`` or more preliminary matches (mutual nearest neighbours passing the ratio
    test ``max_ratio``, COLMAP's own); each photo also keeps its ``min_partners`` best
    partners (ties included) whatever their count, so a photo with weak texture is not cut
    off. Photos the largest model then leaves out get a second chance: each is matched with
    every other photo and the mapping runs again (:mod:`dataset.importers.photos.sfm`): a
    weak link the preliminary matches missed costs time, not photos. Chosen on the
    photo-look renders of the tiny preset (docs/decisions.md, 2026-11-29, "Preemptive
    matching"). A set of at most ``every_pair_up_to`` photos is matched in every pair
    (:func:`matches_every_pair`): there all pairs cost under a minute of CPU (435 pairs
    of 4096 features at about 0.11 s a pair) and every pair adds sparse points, which the
    depth from the sparse points reads."""

    top_features: int = 200
    min_matches: int = 6
    min_partners: int = 5
    max_ratio: float = 0.8
    every_pair_up_to: int = 30

    def __post_init__(self) -> None:
        if self.top_features < 10 or self.min_matches < 1 or self.min_partners < 1:
            raise ValueError(f"top_features must be >= 10, min_matches and min_partners >= 1; "
                             f"got {self.top_features}, {self.min_matches}, "
                             f"{self.min_partners}")
        if not 0.0 < self.max_ratio < 1.0:
            raise ValueError(f"max_ratio must lie in (0, 1), got {self.max_ratio}")
        if self.every_pair_up_to < 0:
            raise ValueError(f"every_pair_up_to must be >= 0, got {self.every_pair_up_to}")


@dataclass(frozen=True)
class ExhaustiveMatching:
    """Match every pair of photos in full (n (n - 1) / 2 pairs: COLMAP's exhaustive
    matcher)."""


def matches_every_pair(matching: PreemptiveMatching | ExhaustiveMatching, photos: int) -> bool:
    """Whether ``photos`` photos are matched in every pair under ``matching``: always for
    :class:`ExhaustiveMatching`; for :class:`PreemptiveMatching`, sets of at most its
    ``every_pair_up_to`` photos."""
    return isinstance(matching, ExhaustiveMatching) or photos <= matching.every_pair_up_to


def keypoint_scales_px(keypoints: np.ndarray) -> np.ndarray:
    """(N,) scale in pixels of COLMAP keypoints: (N, 6) rows x, y, a11, a12, a21, a22 (the
    affine shape; scale sqrt|det A|) or (N, 4) rows x, y, scale, orientation."""
    if keypoints.ndim != 2 or keypoints.shape[1] not in (4, 6):
        raise ValueError(f"keypoints must be (N, 4) or (N, 6) COLMAP rows, got "
                         f"{keypoints.shape}")
    if keypoints.shape[1] == 4:
        return np.abs(keypoints[:, 2]).astype(np.float64)
    a = keypoints[:, 2:6].astype(np.float64)
    return np.sqrt(np.abs(a[:, 0] * a[:, 3] - a[:, 1] * a[:, 2]))


def largest_scale_descriptors(descriptors: np.ndarray, scales_px: np.ndarray,
                              count: int) -> np.ndarray:
    """(min(count, N), D) float32 unit rows: the descriptors ((N, D), any number type) of the
    ``count`` features of largest scale (``scales_px``, (N,)); ties by the descriptor's
    bytes, so the choice does not depend on the features' order."""
    if len(descriptors) != len(scales_px):
        raise ValueError(f"{len(descriptors)} descriptors for {len(scales_px)} scales")
    rows = np.asarray(descriptors, np.float32)
    keys = np.lexsort((*rows.T[::-1], -scales_px))  # scale first, then the bytes
    chosen = rows[keys[:count]]
    norms = np.linalg.norm(chosen, axis=1, keepdims=True)
    return chosen / np.where(norms > 0, norms, 1.0)


def preliminary_match_counts(descriptors: list[np.ndarray], max_ratio: float) -> np.ndarray:
    """(n, n) int symmetric, zero diagonal: for each pair of photos, how many of their
    features are mutual nearest neighbours whose distance is below ``max_ratio`` times the
    second nearest's (both ways). ``descriptors[i]``: (k_i, D) float32 unit rows of photo i
    (:func:`largest_scale_descriptors`); a photo needs 2 or more for the ratio test."""
    n = len(descriptors)
    width = max((len(d) for d in descriptors), default=0)
    dim = descriptors[0].shape[1] if n else 0
    stack = np.zeros((n, width, dim), np.float32)
    valid = np.zeros((n, width), bool)
    for i, d in enumerate(descriptors):
        stack[i, :len(d)], valid[i, :len(d)] = d, True
    counts = np.zeros((n, n), np.int64)
    for i in range(n - 1):
        others = slice(i + 1, n)
        # (m, k, k) cosine similarities of photo i's features (rows) with each later photo's.
        sim = np.matmul(stack[i][None], stack[others].transpose(0, 2, 1))
        sim[:, ~valid[i], :] = -np.inf
        sim[~valid[others][:, None, :].repeat(width, 1)] = -np.inf
        counts[i, others] = _mutual_ratio_matches(sim, max_ratio)
    return counts + counts.T


def _mutual_ratio_matches(sim: np.ndarray, max_ratio: float) -> np.ndarray:
    """(m,) matches in each of ``sim``'s (m, k_a, k_b) similarity blocks: mutual best, and
    passing the ratio test on distances (sqrt(2 - 2 sim) for unit rows) both ways."""
    if sim.shape[1] < 2 or sim.shape[2] < 2:
        return np.zeros(len(sim), np.int64)

    def best_two(s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        top = np.partition(s, -2, axis=2)[:, :, -2:]  # second best, best
        d = np.sqrt(np.maximum(2.0 - 2.0 * top, 0.0))
        return np.argmax(s, axis=2), d[:, :, 1], d[:, :, 0]

    best_b, d1_ab, d2_ab = best_two(sim)  # (m, k_a) each
    best_a, d1_ba, d2_ba = best_two(sim.transpose(0, 2, 1))  # (m, k_b) each
    rows = np.arange(sim.shape[1])[None, :]
    mutual = np.take_along_axis(best_a, best_b, axis=1) == rows
    ratio_ab = d1_ab < max_ratio * d2_ab
    ratio_ba = np.take_along_axis(d1_ba < max_ratio * d2_ba, best_b, axis=1)
    finite = np.isfinite(np.max(sim, axis=2))
    return np.sum(mutual & ratio_ab & ratio_ba & finite, axis=1)


def selected_pairs(counts: np.ndarray, min_matches: int,
                   min_partners: int) -> list[tuple[int, int]]:
    """Pairs (i < j) to match in full, from ``counts`` ((n, n) symmetric preliminary
    matches, :func:`preliminary_match_counts`): those with ``min_matches`` or more, and
    each photo's ``min_partners`` best partners (every partner with as many matches as its
    ``min_partners``-th best, ties included; never a partner with none). Depends on the
    counts alone, not on the photos' order: a permutation of the photos permutes the
    pairs."""
    n = len(counts)
    if counts.shape != (n, n) or not np.array_equal(counts, counts.T):
        raise ValueError(f"counts must be a symmetric (n, n) array, got {counts.shape}")
    off = counts.astype(np.int64).copy()
    np.fill_diagonal(off, -1)
    keep = off >= min_matches
    if n > 1:
        rank = min(min_partners, n - 1)
        nth_best = -np.partition(-off, rank - 1, axis=1)[:, rank - 1]  # (n,)
        best = (off >= nth_best[:, None]) & (off > 0)
        keep |= best | best.T
    i, j = np.nonzero(np.triu(keep, k=1))
    return list(zip(i.tolist(), j.tolist()))
