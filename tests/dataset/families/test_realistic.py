"""Realistic family: every model agrees with its mesh and falls in the family's ranges."""

import numpy as np
import pytest
from building_checks import check_building

from dataset.families.realistic import (
    FLOORS_RANGE,
    FOOTPRINT_RANGE_M2,
    HEIGHT_RANGE_M,
    WWR_RANGE,
    make_realistic,
    realistic_layout,
    sample_realistic_params,
)
from dataset.families.realistic_params import (
    REALISTIC_MODELS,
    RealisticParams,
    default_realistic_params,
)


@pytest.mark.parametrize("model", REALISTIC_MODELS)
def test_sampled_model_matches_its_mesh_and_ranges(model):
    params = sample_realistic_params(np.random.default_rng(11), model)
    building = make_realistic(params, seed=11)
    t = building.truth
    check_building(building)
    assert t.type == "realistic" and t.name == model and t.id == f"realistic_{model}"
    assert FLOORS_RANGE[0] <= t.floors <= FLOORS_RANGE[1]
    assert HEIGHT_RANGE_M[0] <= t.height_m <= HEIGHT_RANGE_M[1]
    assert FOOTPRINT_RANGE_M2[0] <= t.footprint_area_m2 <= FOOTPRINT_RANGE_M2[1]
    assert WWR_RANGE[0] <= t.wwr <= WWR_RANGE[1]
    assert t.door_area_m2 > 0
    assert t.extra["params"]["model"] == model


@pytest.mark.parametrize("model", REALISTIC_MODELS)
def test_jittered_sizes_stay_in_the_ranges_at_their_extremes(model):
    # The sampler scales sizes by 0.95..1.05; the extreme corners must stay in range too.
    base = default_realistic_params(model)
    for s in (0.95, 1.05):
        p = RealisticParams(model, base.width_m * s, base.depth_m * s, base.floors,
                            base.floor_height_m * (0.98 if s < 1 else 1.03), base.roof_m * s,
                            base.window_width_m * s, base.window_height_m * s)
        t = make_realistic(p).truth
        assert HEIGHT_RANGE_M[0] <= t.height_m <= HEIGHT_RANGE_M[1], (model, s, t.height_m)
        assert FOOTPRINT_RANGE_M2[0] <= t.footprint_area_m2 <= FOOTPRINT_RANGE_M2[1]
        assert WWR_RANGE[0] <= t.wwr <= WWR_RANGE[1], (model, s, t.wwr)


def test_bad_parameters_raise_helpful_errors():
    with pytest.raises(ValueError, match="unknown realistic model"):
        RealisticParams("castle")
    with pytest.raises(ValueError, match="unknown realistic model"):
        default_realistic_params("castle")
    with pytest.raises(ValueError, match="floors must be >= 1"):
        RealisticParams("house", floors=0)
    with pytest.raises(ValueError, match="width_m must be > 0"):
        RealisticParams("rounded", width_m=-2.0)
    with pytest.raises(ValueError, match="do not fit|does not fit"):
        realistic_layout(RealisticParams("house", window_width_m=4.0))
