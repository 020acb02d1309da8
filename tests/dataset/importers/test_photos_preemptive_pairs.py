"""dataset.importers.photos.preemptive_pairs: the pairs preemptive matching keeps, on
features built so that the preliminary matches are known in closed form, and the same pairs
whatever the photos' order."""

from __future__ import annotations

import numpy as np
import pytest

from dataset.importers.photos.preemptive_pairs import (
    ExhaustiveMatching,
    PreemptiveMatching,
    keypoint_scales_px,
    largest_scale_descriptors,
    matches_every_pair,
    preliminary_match_counts,
    selected_pairs,
)

RING = 12
"""Photos round a building: photo i shares ``SHARED[d]`` features with photo i + d."""
SHARED = {1: 8, 2: 3}
DIM = 128


def _ring_descriptors(rng: np.random.Generator) -> list[np.ndarray]:
    """(k_i, 128) unit rows per photo: each feature seen by a pair of photos (per
    :data:`SHARED`) appears in both, with a little noise; the rest are random (random unit
    vectors in 128 dimensions lie near sqrt(2) apart, so they fail the ratio test)."""
    rows: list[list[np.ndarray]] = [[] for _ in range(RING)]
    for i in range(RING):
        for step, count in SHARED.items():
            for _ in range(count):
                feature = rng.normal(size=DIM)
                for photo in (i, (i + step) % RING):
                    rows[photo].append(feature + 0.05 * rng.normal(size=DIM))
    for photo in rows:
        photo.extend(rng.normal(size=DIM) for _ in range(20))
    out = []
    for photo in rows:
        d = np.abs(np.array(photo, np.float32))  # SIFT descriptors are non-negative
        out.append(d / np.linalg.norm(d, axis=1, keepdims=True))
    return out


def _ring_counts() -> np.ndarray:
    """(RING, RING): the preliminary matches the ring is built to give."""
    counts = np.zeros((RING, RING), np.int64)
    for i in range(RING):
        for step, count in SHARED.items():
            j = (i + step) % RING
            counts[i, j] = counts[j, i] = count
    return counts


def test_preliminary_matches_are_the_shared_features():
    descriptors = _ring_descriptors(np.random.default_rng(0))
    counts = preliminary_match_counts(descriptors, PreemptiveMatching().max_ratio)
    np.testing.assert_array_equal(counts, _ring_counts())


def test_pairs_are_those_with_enough_matches_and_each_photos_best():
    counts = _ring_counts()
    # Threshold 5: only the next-door pairs; one best partner each adds nothing (its best
    # are next door too).
    assert selected_pairs(counts, 5, 1) == sorted((min(i, (i + 1) % RING),
                                                   max(i, (i + 1) % RING))
                                                  for i in range(RING))
    # Threshold above every count: each photo's 3 best partners are its two next-door
    # photos (8 each) and its two second-door photos (3, tied: both kept).
    assert len(selected_pairs(counts, 100, 3)) == RING * 2
    # A photo with no match at all is never paired, whatever min_partners asks.
    lonely = np.zeros((3, 3), np.int64)
    lonely[0, 1] = lonely[1, 0] = 2
    assert selected_pairs(lonely, 10, 2) == [(0, 1)]


def test_a_permutation_of_the_photos_permutes_the_pairs():
    descriptors = _ring_descriptors(np.random.default_rng(1))
    order = np.random.default_rng(2).permutation(RING)  # new index k holds photo order[k]
    config = PreemptiveMatching()
    pairs = selected_pairs(preliminary_match_counts(descriptors, config.max_ratio),
                           config.min_matches, config.min_partners)
    shuffled = selected_pairs(preliminary_match_counts([descriptors[k] for k in order],
                                                       config.max_ratio),
                              config.min_matches, config.min_partners)
    assert sorted(tuple(sorted((int(order[a]), int(order[b])))) for a, b in shuffled) == pairs


def test_largest_scale_features_are_kept_from_the_affine_shape():
    rng = np.random.default_rng(3)
    scales = np.array([2.0, 9.0, 0.5, 4.0])
    turns = rng.uniform(0, 2 * np.pi, 4)
    # COLMAP's affine shape: scale times a rotation.
    a = np.stack([scales * np.cos(turns), -scales * np.sin(turns),
                  scales * np.sin(turns), scales * np.cos(turns)], axis=1)
    keypoints = np.hstack([rng.uniform(0, 100, (4, 2)), a]).astype(np.float32)
    np.testing.assert_allclose(keypoint_scales_px(keypoints), scales, rtol=1e-5)
    descriptors = np.eye(4, DIM, dtype=np.uint8) * 200
    kept = largest_scale_descriptors(descriptors, scales, 2)
    np.testing.assert_array_equal(kept, np.eye(4, DIM, dtype=np.float32)[[1, 3]])


def test_bad_settings_and_shapes_are_refused():
    with pytest.raises(ValueError, match="min_matches"):
        PreemptiveMatching(min_matches=0)
    with pytest.raises(ValueError, match="max_ratio"):
        PreemptiveMatching(max_ratio=1.0)
    with pytest.raises(ValueError, match="symmetric"):
        selected_pairs(np.triu(np.ones((3, 3), np.int64), 1), 1, 1)
    with pytest.raises(ValueError, match=r"\(N, 4\) or \(N, 6\)"):
        keypoint_scales_px(np.zeros((3, 5)))
    with pytest.raises(ValueError, match="every_pair_up_to"):
        PreemptiveMatching(every_pair_up_to=-1)


def test_small_sets_are_matched_in_every_pair():
    # 30 photos (435 pairs) or fewer: every pair; above, the preemptive pairs.
    assert matches_every_pair(PreemptiveMatching(), 30)
    assert not matches_every_pair(PreemptiveMatching(), 31)
    assert not matches_every_pair(PreemptiveMatching(every_pair_up_to=0), 3)
    assert matches_every_pair(ExhaustiveMatching(), 1000)
