"""Augmentation: the crop is the frame's pixels where nothing random applies, labels follow the
geometry exactly, photometric changes stay in range, outside pixels are ignored."""

from dataclasses import replace

import numpy as np
import pytest

from segment.augment import IGNORE_LABEL, AugmentConfig, augment_frame

# Nothing random but the crop position: no zoom, flip, colour, blur, noise or JPEG.
IDENTITY = AugmentConfig(
    crop_px=16, scale=(1.0, 1.0), flip_p=0.0, brightness=(1, 1), contrast=(1, 1),
    saturation=(1, 1), channel_gain=(1, 1), gamma=(1, 1), blur_p=0.0, noise_p=0.0, jpeg_p=0.0)


def _frame(h=40, w=60):
    rng = np.random.default_rng(1)
    rgb = rng.integers(0, 256, (h, w, 3), dtype=np.uint8)
    labels = np.zeros((h, w), np.uint8)
    labels[10:30, 20:50] = 1
    labels[15:20, 25:30] = 2
    return rgb, labels


def _locate(crop_rgb: np.ndarray, rgb: np.ndarray) -> tuple[int, int]:
    """(top, left) of the crop in the frame, from a pixel-exact match."""
    target = np.round(crop_rgb[0, 0] * 255).astype(np.uint8)
    for y, x in zip(*np.nonzero((rgb == target).all(axis=2))):
        h, w = crop_rgb.shape[:2]
        window = rgb[y:y + h, x:x + w]
        if window.shape[:2] == (h, w) and (np.round(crop_rgb * 255) == window).all():
            return int(y), int(x)
    raise AssertionError("crop not found in the frame")


def test_identity_augmentation_crops_rgb_and_labels_alike():
    rgb, labels = _frame()
    rng = np.random.default_rng(0)
    checked = 0
    for _ in range(20):
        x, y = augment_frame(rgb, labels, IDENTITY, rng)
        assert x.shape == (16, 16, 3) and x.dtype == np.float32
        assert y.shape == (16, 16) and y.dtype == np.int64
        if (y != IGNORE_LABEL).all():
            top, left = _locate(x, rgb)
            assert (y == labels[top:top + 16, left:left + 16]).all()
            checked += 1
    assert checked >= 10


def test_crops_reaching_outside_the_frame_are_ignored_there():
    rgb, labels = _frame(8, 8)  # smaller than the crop: every crop reaches outside
    x, y = augment_frame(rgb, labels, IDENTITY, np.random.default_rng(0))
    outside = y == IGNORE_LABEL
    assert outside.sum() >= 16 * 16 - 8 * 8
    assert (x[outside] == 0).all()


def test_building_centred_crops_hold_building_pixels():
    rgb, labels = _frame(200, 200)
    labels[:] = 0
    labels[150:160, 150:160] = 1
    config = replace(IDENTITY, building_centre_p=1.0)
    rng = np.random.default_rng(0)
    assert all((augment_frame(rgb, labels, config, rng)[1] == 1).any() for _ in range(10))


def test_random_augmentation_keeps_labels_and_ranges():
    rgb, labels = _frame()
    rng = np.random.default_rng(0)
    config = AugmentConfig(crop_px=32, blur_p=1.0, noise_p=1.0, jpeg_p=1.0, flip_p=0.5)
    for _ in range(20):
        x, y = augment_frame(rgb, labels, config, rng)
        assert x.min() >= 0 and x.max() <= 1
        assert set(np.unique(y)) <= {0, 1, 2, IGNORE_LABEL}


def test_bad_configs_are_refused():
    with pytest.raises(ValueError, match="crop_px"):
        AugmentConfig(crop_px=4)
    with pytest.raises(ValueError, match="scale"):
        AugmentConfig(scale=(2.0, 1.0))
