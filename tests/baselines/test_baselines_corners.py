"""baselines.corners: enclosing quadrilateral of facade masks, ordering, the border check."""

import numpy as np
import pytest

from baselines.corners import (
    corners_inside_image,
    enclosing_quadrilateral,
    minimum_area_quadrilateral,
    order_corners,
)
from baselines.views import ViewError


def _raster(quad: np.ndarray, h: int = 300, w: int = 400) -> np.ndarray:
    """(H, W) bool mask of pixels whose centre lies inside the convex polygon ``quad``."""
    uu, vv = np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5)
    inside = np.ones((h, w), bool)
    n = len(quad)
    area2 = sum(quad[i, 0] * quad[(i + 1) % n, 1] - quad[(i + 1) % n, 0] * quad[i, 1]
                for i in range(n))
    for i in range(n):
        a, b = quad[i], quad[(i + 1) % n]
        cross = (b[0] - a[0]) * (vv - a[1]) - (b[1] - a[1]) * (uu - a[0])
        inside &= cross * np.sign(area2) >= 0
    return inside


def test_cut_corner_square_gives_back_the_square_exactly():
    # A 10 x 10 square with all four corners cut by 1 unit: the octagon's
    # minimum enclosing quadrilateral is the square.
    octagon = np.array([[1, 0], [9, 0], [10, 1], [10, 9], [9, 10], [1, 10], [0, 9], [0, 1.0]])
    quad = order_corners(minimum_area_quadrilateral(octagon))
    np.testing.assert_allclose(quad, [[0, 0], [10, 0], [10, 10], [0, 10]], atol=1e-12)


@pytest.mark.parametrize("quad", [
    np.array([[60.3, 40.7], [340.2, 70.1], [330.6, 260.4], [75.1, 230.9]]),  # perspective
    np.array([[50.0, 50.0], [350.0, 50.0], [350.0, 250.0], [50.0, 250.0]]),  # grid-aligned
    np.array([[100.4, 30.2], [300.7, 30.2], [360.1, 280.8], [40.3, 280.8]]),  # keystone
])
def test_rasterised_quadrilateral_corners_within_half_a_pixel(quad):
    corners = enclosing_quadrilateral(_raster(quad))
    np.testing.assert_allclose(corners, quad, atol=0.5)


def test_windows_and_a_notch_do_not_move_the_corners():
    quad = np.array([[60.3, 40.7], [340.2, 70.1], [330.6, 260.4], [75.1, 230.9]])
    mask = _raster(quad)
    mask[100:130, 120:160] = False  # a hole (an occluder) inside the facade
    mask[225:260, 180:200] = False  # a notch at the bottom edge (a recessed door)
    np.testing.assert_allclose(enclosing_quadrilateral(mask), quad, atol=0.5)


def test_order_is_top_left_clockwise_on_screen():
    shuffled = np.array([[10, 90], [90, 10], [10, 10], [90, 90.0]])
    np.testing.assert_array_equal(order_corners(shuffled),
                                  [[10, 10], [90, 10], [90, 90], [10, 90]])


def test_corners_on_the_border_mean_a_cut_off_facade():
    corners = np.array([[0.2, 10], [50, 10], [50, 40], [0.2, 40]])
    with pytest.raises(ViewError, match=r"\(0.2, 10.0\).*cut off"):
        corners_inside_image(corners, 64, 48, margin_px=1.0)
    corners_inside_image(corners + [5, 0], 64, 48, margin_px=1.0)  # inside: no error


def test_empty_or_tiny_masks_are_refused():
    with pytest.raises(ViewError, match="empty"):
        enclosing_quadrilateral(np.zeros((20, 20), bool))
    tiny = np.zeros((20, 20), bool)
    tiny[5, 5:7] = True
    with pytest.raises(ViewError, match="too small"):
        enclosing_quadrilateral(tiny)
    with pytest.raises(ValueError, match=r"\(H, W\)"):
        enclosing_quadrilateral(np.zeros(5, bool))


def test_pixel_block_corners_are_its_outer_pixel_edges():
    # Pixels [10, 20) x [5, 15): OpenCV reports integer pixel indices; the corners
    # must be the block's outer edges in continuous coordinates (centres at +0.5).
    mask = np.zeros((30, 30), bool)
    mask[5:15, 10:20] = True
    np.testing.assert_allclose(enclosing_quadrilateral(mask),
                               [[10, 5], [20, 5], [20, 15], [10, 15]], atol=1e-9)
