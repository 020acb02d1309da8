"""Skyscraper family: closed-form truth of the default tower, mesh checks, sampler ranges."""

import numpy as np
import pytest
from building_checks import check_building

from dataset.families.grid_prism import RoofSpec, WindowSpec
from dataset.families.skyscraper import (
    FLOORS_RANGE,
    FOOTPRINT_RANGE_M2,
    HEIGHT_RANGE_M,
    WWR_RANGE,
    SkyscraperParams,
    make_skyscraper,
    sample_skyscraper_params,
)


def test_default_tower_truth_is_closed_form_and_matches_its_mesh():
    p = SkyscraperParams()  # 7 x 6 m, 10 floors of 2.8 m, 1 m parapet, 3 + 2 columns
    building = make_skyscraper(p, building_id="t", seed=5)
    t = building.truth
    assert t.height_m == pytest.approx(29.0) and t.floors == 10
    assert t.footprint_area_m2 == pytest.approx(42.0)
    assert t.facade_area_m2 == pytest.approx(2 * (7 + 6) * 29.0)
    # 3 columns at 7 m with 0.6 m margins: bays of 1.933 m centred at 1.567, 3.5, 5.433 m;
    # the 1.2 m door at 3.5 m displaces the middle ground-floor window.
    n_windows = 10 * 2 * (3 + 2) - 1
    assert t.window_area_m2 == pytest.approx(n_windows * 1.2 * 1.4)
    assert t.door_area_m2 == pytest.approx(1.2 * 2.2)
    assert [f.id for f in t.facades] == [1, 2, 3, 4]
    assert t.facades[0].normal == (0.0, -1.0, 0.0)
    assert t.seed == 5 and t.type == "skyscraper" and t.id == "t"
    check_building(building)


def test_overhang_tower_matches_its_mesh():
    p = SkyscraperParams(roof=RoofSpec("overhang", overhang_m=0.6, thickness_m=0.3))
    building = make_skyscraper(p)
    assert building.truth.height_m == pytest.approx(28.3)
    check_building(building)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_sampled_towers_fall_in_the_family_ranges(seed):
    p = sample_skyscraper_params(np.random.default_rng(seed))
    t = make_skyscraper(p, seed=seed).truth
    assert FLOORS_RANGE[0] <= t.floors <= FLOORS_RANGE[1]
    assert HEIGHT_RANGE_M[0] <= t.height_m <= HEIGHT_RANGE_M[1]
    assert FOOTPRINT_RANGE_M2[0] <= t.footprint_area_m2 <= FOOTPRINT_RANGE_M2[1]
    assert WWR_RANGE[0] <= t.wwr <= WWR_RANGE[1]
    assert 2.7 <= p.floor_height_m <= 3.0
    assert 0.05 <= p.windows.reveal_m <= 0.08


def test_same_seed_same_parameters():
    a = sample_skyscraper_params(np.random.default_rng(7))
    b = sample_skyscraper_params(np.random.default_rng(7))
    assert a == b


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"floors": 0}, "floors must be >= 1"),
        ({"floors": -3}, "floors must be >= 1"),
        ({"width_m": 0.0}, "footprint must be > 0"),
        ({"columns_front": 6}, "do not fit"),
        ({"windows": WindowSpec(window_width_m=8.0)}, "do not fit"),
        ({"windows": WindowSpec(window_height_m=2.5)}, "exceed the floor height"),
        ({"floor_height_m": 2.0}, "taller than the ground floor"),
    ],
)
def test_impossible_towers_raise_helpful_errors(kwargs, message):
    with pytest.raises(ValueError, match=message):
        SkyscraperParams(**kwargs)
