"""baselines.weighting: building WWR under equal, alpha (L/H) and area (L H) weights, by hand."""

import numpy as np
import pytest

from baselines.weighting import facade_weights, weighted_building_wwr

# Three hand-made facades: WWR, length L and height H.
WWR = np.array([0.2, 0.4, 0.1])
L = np.array([20.0, 10.0, 12.0])
H = np.array([10.0, 10.0, 4.0])


def test_equal_weighting_is_the_plain_mean():
    w = facade_weights("equal", count=3)
    assert weighted_building_wwr(WWR, w) == pytest.approx(0.7 / 3)


def test_alpha_weighting_by_hand():
    # alpha = 2, 1, 3: (0.4 + 0.4 + 0.3) / 6
    w = facade_weights("alpha", L, H)
    np.testing.assert_allclose(w, [2, 1, 3])
    assert weighted_building_wwr(WWR, w) == pytest.approx(1.1 / 6)


def test_area_weighting_is_total_window_over_total_facade():
    # A = 200, 100, 48: windows 40 + 40 + 4.8 = 84.8 m² of 348 m²
    w = facade_weights("area", L, H)
    np.testing.assert_allclose(w, [200, 100, 48])
    assert weighted_building_wwr(WWR, w) == pytest.approx(84.8 / 348)


def test_alpha_equals_area_when_heights_are_equal():
    h = np.full(3, 7.0)
    assert weighted_building_wwr(WWR, facade_weights("alpha", L, h)) == pytest.approx(
        weighted_building_wwr(WWR, facade_weights("area", L, h)))


def test_bad_inputs_say_what_is_wrong():
    with pytest.raises(ValueError, match="unknown weighting"):
        facade_weights("height", L, H)
    with pytest.raises(ValueError, match="needs facade lengths"):
        facade_weights("alpha")
    with pytest.raises(ValueError, match="> 0 m"):
        facade_weights("area", L, np.array([1.0, 0.0, 2.0]))
    with pytest.raises(ValueError, match="N >= 1"):
        weighted_building_wwr(np.array([]), np.array([]))
    with pytest.raises(ValueError, match="sum to > 0"):
        weighted_building_wwr(WWR, np.zeros(3))
