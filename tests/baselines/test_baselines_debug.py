"""baselines.debug: predictable debug image names, colours, corner drawing."""

from pathlib import Path

import numpy as np

from baselines.debug import colour_labels, debug_image_path, draw_corners, write_debug_image
from envelope.scenes.images import read_rgb


def test_names_are_predictable():
    p = debug_image_path(Path("d"), "tiny_l_shaped_1", "multi", 3, 4, "rectified")
    assert p == Path("d/tiny_l_shaped_1__multi__f3__v4__rectified.png")


def test_colours_dim_outside_the_mask_and_drawing_keeps_the_input(tmp_path):
    labels = np.array([[0, 1], [2, 4]], np.uint8)
    rgb = colour_labels(labels, mask=np.array([[True, True], [False, True]]))
    assert rgb.shape == (2, 2, 3) and rgb.dtype == np.uint8
    assert (rgb[1, 0] == colour_labels(labels)[1, 0] // 4).all()
    img = np.zeros((40, 60, 3), np.uint8)
    drawn = draw_corners(img, np.array([[10, 10], [50, 10], [50, 30], [10, 30.0]]))
    assert img.max() == 0 and drawn.max() > 0  # a copy, with the quadrilateral on it
    path = write_debug_image(tmp_path, "s", "ideal", 1, 0, "corners", drawn)
    np.testing.assert_array_equal(read_rgb(path), drawn)
