"""L-shaped family: footprint and facades in closed form, mesh checks, sampler ranges."""

import numpy as np
import pytest
from building_checks import check_building

from dataset.families.grid_prism import RoofSpec
from dataset.families.l_shaped import (
    FLOORS_RANGE,
    FOOTPRINT_RANGE_M2,
    HEIGHT_RANGE_M,
    WWR_RANGE,
    LShapedParams,
    l_shaped_footprint,
    make_l_shaped,
    sample_l_shaped_params,
)


def test_default_l_truth_is_closed_form_and_matches_its_mesh():
    p = LShapedParams()  # 16 x 14 m, wings 7 m, 4 floors of 2.8 m, 1 m parapet
    building = make_l_shaped(p)
    t = building.truth
    assert t.footprint_area_m2 == pytest.approx(16 * 7 + 7 * 7)
    assert len(t.facades) == 6
    widths = [f.width_m for f in t.facades]
    np.testing.assert_allclose(widths, [16, 7, 9, 7, 7, 14])
    assert t.facade_area_m2 == pytest.approx(2 * (16 + 14) * (4 * 2.8 + 1.0))
    normals = [f.normal[:2] for f in t.facades]
    np.testing.assert_allclose(normals, [[0, -1], [1, 0], [0, 1], [1, 0], [0, 1], [-1, 0]],
                               atol=1e-12)
    assert t.door_area_m2 == pytest.approx(2 * 1.2 * 2.2)  # facades 1 and 3
    check_building(building)


def test_footprint_has_one_concave_corner_and_is_centred():
    fp = l_shaped_footprint(LShapedParams())
    np.testing.assert_allclose(fp.min(axis=0), -fp.max(axis=0))
    d1, d2 = np.roll(fp, -1, axis=0) - fp, fp - np.roll(fp, 1, axis=0)
    turns = d2[:, 0] * d1[:, 1] - d2[:, 1] * d1[:, 0]
    assert (turns < 0).sum() == 1  # one right turn on a counter-clockwise ring


def test_overhang_l_matches_its_mesh():
    building = make_l_shaped(LShapedParams(roof=RoofSpec("overhang", overhang_m=0.5)))
    check_building(building)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_sampled_l_shapes_fall_in_the_family_ranges(seed):
    t = make_l_shaped(sample_l_shaped_params(np.random.default_rng(seed))).truth
    assert FLOORS_RANGE[0] <= t.floors <= FLOORS_RANGE[1]
    assert HEIGHT_RANGE_M[0] <= t.height_m <= HEIGHT_RANGE_M[1]
    assert FOOTPRINT_RANGE_M2[0] <= t.footprint_area_m2 <= FOOTPRINT_RANGE_M2[1]
    assert WWR_RANGE[0] <= t.wwr <= WWR_RANGE[1]


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"floors": 0}, "floors must be >= 1"),
        ({"wing_x_m": -1.0}, "wing widths must be > 0"),
        ({"length_x_m": 8.0}, "stick out"),
        ({"columns": (5, 2, 3, 2, 2)}, "one column count per footprint edge"),
        ({"columns": (5, 9, 3, 2, 2, 5)}, "do not fit"),
    ],
)
def test_impossible_l_shapes_raise_helpful_errors(kwargs, message):
    with pytest.raises(ValueError, match=message):
        LShapedParams(**kwargs)
