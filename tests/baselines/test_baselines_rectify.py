"""baselines.rectify: homography round trip, the pixel convention of the kornia warp, WWR."""

import numpy as np
import pytest
import torch

from baselines.rectify import (
    OUTSIDE,
    quadrilateral_area_px,
    rectangle_size_px,
    rectified_from_image,
    rectified_wwr,
    rectify_labels,
)


def test_homography_maps_the_corners_onto_the_rectangle():
    corners = np.array([[[60.3, 40.7], [340.2, 70.1], [330.6, 260.4], [75.1, 230.9]],
                        [[10.0, 10.0], [20.0, 10.0], [20.0, 30.0], [10.0, 30.0]]])
    sizes = np.array([[300, 200], [100, 200]])
    h = rectified_from_image(corners, sizes).numpy()
    homog = np.concatenate([corners, np.ones((2, 4, 1))], axis=-1) @ h.transpose(0, 2, 1)
    mapped = homog[..., :2] / homog[..., 2:]
    unit_square = np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]])
    expected = unit_square[None] * sizes[:, None, :]
    np.testing.assert_allclose(mapped, expected, atol=1e-6)
    # ... and back: the inverse maps the rectangle corners onto the image corners.
    back = np.concatenate([expected, np.ones((2, 4, 1))], -1) @ np.linalg.inv(h).transpose(0, 2, 1)
    np.testing.assert_allclose(back[..., :2] / back[..., 2:], corners, atol=1e-6)


def test_warp_uses_pixel_centres_at_half_integers():
    # Doubling a 32 x 24 label image: output pixel x (centre x + 0.5) samples
    # input (x + 0.5) / 2, i.e. pixel x // 2, only if both sides agree on centres.
    rng = np.random.default_rng(0)
    labels = rng.integers(0, 6, (24, 32)).astype(np.uint8)
    corners = np.array([[[0, 0], [32, 0], [32, 24], [0, 24.0]]])
    out = rectify_labels(labels[None], corners, np.array([[64, 48]]))
    assert out.shape == (1, 48, 64)
    np.testing.assert_array_equal(out[0], labels.repeat(2, 0).repeat(2, 1))


def test_a_batch_shares_the_largest_canvas_and_marks_the_rest_outside():
    labels = np.ones((2, 24, 32), np.uint8)
    corners = np.array([[[0, 0], [32, 0], [32, 24], [0, 24.0]]] * 2)
    out = rectify_labels(labels, corners, np.array([[64, 48], [16, 30]]))
    assert out.shape == (2, 48, 64)
    assert (out[0] == 1).all()
    assert (out[1, :30, :16] == 1).all() and (out[1, 30:] == OUTSIDE).all()
    assert (out[1, :, 16:] == OUTSIDE).all()


def test_rectified_translation_crops_the_quadrilateral():
    labels = np.zeros((40, 50), np.uint8)
    labels[10:30, 5:45] = 1
    labels[15:20, 10:20] = 2
    corners = np.array([[[5, 10], [45, 10], [45, 30], [5, 30.0]]])
    out = rectify_labels(labels[None], corners, np.array([[40, 20]]), device=torch.device("cpu"))
    np.testing.assert_array_equal(out[0], labels[10:30, 5:45])
    assert rectified_wwr(out)[0] == pytest.approx(50 / 800)


def test_rectified_wwr_counts_facade_classes_only():
    r = np.full((2, 4, 4), OUTSIDE, np.uint8)
    r[0, :2, :2] = [[1, 2], [4, 3]]  # wall, window, door, roof: 1 window of 3 facade pixels
    r[1, 0, 0] = 0  # background only
    wwr = rectified_wwr(r)
    assert wwr[0] == pytest.approx(1 / 3)
    assert np.isnan(wwr[1])


def test_rectangle_keeps_the_area_and_aspect_within_the_cap():
    assert rectangle_size_px(2.0, 20000.0, 1024) == (200, 100)
    assert rectangle_size_px(0.25, 10000.0, 1024) == (50, 200)
    assert rectangle_size_px(2.0, 20000.0, 100) == (100, 50)  # capped, aspect kept
    assert rectangle_size_px(1.0, 0.01, 100) == (1, 1)
    with pytest.raises(ValueError, match="positive"):
        rectangle_size_px(float("nan"), 100.0, 512)
    with pytest.raises(ValueError, match="area_px"):
        rectangle_size_px(1.0, 0.0, 512)


def test_quadrilateral_area_by_shoelace():
    assert quadrilateral_area_px(np.array([[0, 0], [4, 0], [4, 3], [0, 3.0]])) == 12.0
    assert quadrilateral_area_px(np.array([[0, 0], [4, 0], [3, 2], [1, 2.0]])) == 6.0


def test_bad_inputs_say_what_is_wrong():
    with pytest.raises(ValueError, match=r"\(B, 4, 2\)"):
        rectified_from_image(np.zeros((4, 2)), np.ones((1, 2)))
    with pytest.raises(ValueError, match="sizes"):
        rectify_labels(np.zeros((1, 8, 8), np.uint8), np.zeros((1, 4, 2)), np.array([[0, 4]]))
    with pytest.raises(ValueError, match=r"\(B, H, W\)"):
        rectify_labels(np.zeros((8, 8), np.uint8), np.zeros((1, 4, 2)), np.array([[4, 4]]))
