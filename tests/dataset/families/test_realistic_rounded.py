"""The rounded model: one curved facade of planar facets, its width the summed chords."""

import numpy as np
import pytest

from dataset.families.realistic import make_realistic
from dataset.families.realistic_params import RealisticParams
from dataset.families.realistic_rounded import CURVED_FACADE_ID, rounded_footprint


def test_curved_facade_width_and_footprint_are_closed_form():
    p = RealisticParams("rounded", width_m=17.0, depth_m=11.0, floors=5, floor_height_m=3.1,
                        roof_m=1.0, window_width_m=1.2, window_height_m=1.5)
    t = make_realistic(p).truth
    r = 5.5
    facets = t.extra["curved_facade"]["facets"]
    curved = t.facade(CURVED_FACADE_ID)
    assert curved.curved and not t.facade(1).curved
    assert curved.width_m == pytest.approx(facets * 2 * r * np.sin(np.pi / (2 * facets)))
    np.testing.assert_allclose(curved.normal, [1.0, 0.0, 0.0], atol=1e-12)
    half_disc = facets / 2 * r * r * np.sin(np.pi / facets)
    assert t.footprint_area_m2 == pytest.approx((17.0 - r) * 2 * r + half_disc)
    assert curved.facade_area_m2 == pytest.approx(curved.width_m * (5 * 3.1 + 1.0))
    assert curved.window_area_m2 > 0


def test_footprint_is_centred_with_exact_arc_ends():
    fp, facets = rounded_footprint(17.0, 11.0)
    assert len(fp) == facets + 3
    np.testing.assert_allclose(fp.min(axis=0), [-8.5, -5.5])
    np.testing.assert_allclose(fp.max(axis=0), [8.5, 5.5])
    np.testing.assert_allclose(np.linalg.norm(fp[1:facets + 2] - [3.0, 0.0], axis=1), 5.5)


def test_rounded_without_straight_part_raises():
    with pytest.raises(ValueError, match="a straight part"):
        rounded_footprint(7.0, 11.0)  # 1.5 m of straight wall before the half-round
