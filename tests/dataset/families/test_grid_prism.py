"""Grid-windowed prisms: doors displace windows, roof heights, WWR from parameters, bad input."""

import numpy as np
import pytest

from dataset.families.grid_prism import (
    RoofSpec,
    WindowSpec,
    grid_prism_building,
    grid_prism_walls,
    grid_prism_wwr,
)

RECT = np.array([[-5.0, -4.0], [5.0, -4.0], [5.0, 4.0], [-5.0, 4.0]])
WINDOWS = WindowSpec(window_width_m=1.0, window_height_m=1.5, sill_height_m=0.8, margin_m=1.0,
                     door_width_m=1.2, door_height_m=2.2)


def _walls(roof: RoofSpec | None = None, **kwargs):
    args = dict(floors=3, floor_height_m=3.0, columns=(4, 3, 4, 3), windows=WINDOWS,
                door_edges=(0,), roof=roof or RoofSpec())
    args.update(kwargs)
    return grid_prism_walls(RECT, **args)


def test_door_replaces_the_windows_it_would_touch():
    walls = _walls()
    south = walls[0].openings
    assert sum(o.kind == "door" for o in south) == 1
    # 4 columns at u = 2, 4, 6, 8: the 1.2 m door at u = 5 touches the 1 m windows at 4 and 6.
    assert sum(o.kind == "window" for o in south) == 3 * 4 - 2
    assert all(o.kind == "window" for o in walls[2].openings) and len(walls[2].openings) == 12


def test_walls_reach_the_parapet_top_and_wwr_is_closed_form():
    walls = _walls(RoofSpec("parapet", parapet_height_m=1.2))
    assert {w.height_m for w in walls} == {10.2}
    n_windows = 3 * (4 + 3 + 4 + 3) - 2
    gross = 2 * (10 + 8) * 10.2
    assert grid_prism_wwr(walls) == pytest.approx(n_windows * 1.5 / gross, rel=1e-12)
    assert {w.height_m for w in _walls(RoofSpec("overhang"))} == {9.0}


def test_building_height_includes_the_roof_construction():
    roof = RoofSpec("overhang", overhang_m=0.4, thickness_m=0.35)
    building = grid_prism_building(RECT, _walls(roof), floors=3, floor_height_m=3.0, roof=roof,
                                   building_id="b", building_type="skyscraper", seed=1, params={})
    assert building.truth.height_m == pytest.approx(9.35)
    assert building.mesh.vertices_m[:, 2].max() == pytest.approx(9.35)
    assert building.truth.extra["roof"]["kind"] == "overhang"


def test_bad_grids_raise_helpful_errors():
    with pytest.raises(ValueError, match="floors must be >= 1"):
        _walls(floors=0)
    with pytest.raises(ValueError, match="one column count per footprint edge"):
        _walls(columns=(4, 3))
    with pytest.raises(ValueError, match="door edges"):
        _walls(door_edges=(7,))
    with pytest.raises(ValueError, match="taller than the ground floor"):
        _walls(floor_height_m=2.3)
    with pytest.raises(ValueError, match="do not fit"):
        _walls(columns=(9, 3, 4, 3))
    with pytest.raises(ValueError, match="roof kind"):
        RoofSpec("dome")
    with pytest.raises(ValueError, match="must be > 0"):
        RoofSpec("parapet", parapet_height_m=-1.0)
