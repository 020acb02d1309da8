"""Analytic truth from walls: per-facade sums, normals, outlines, and the assembled building."""

import numpy as np
import pytest
from building_checks import check_building

from dataset.families.building_assembly import (
    BuildingLayout,
    assemble_building,
    assemble_layout,
    facade_outlines_m,
    facade_truths,
)
from dataset.families.facade_geometry import Opening
from dataset.families.prism import ground_face, parapet_roof_faces, prism_walls

RECT = np.array([[-4.0, -3.0], [4.0, -3.0], [4.0, 3.0], [-4.0, 3.0]])


def _walls():
    window, door = Opening("window", 1.0, 1.0, 3.0, 2.5), Opening("door", 3.0, 0.1, 4.0, 2.2)
    openings = [[window], [], [door], []]
    return prism_walls(RECT, 5.0, [1, 2, 3, 4], openings)


def test_facade_truths_are_closed_form():
    south, east, north, _ = facade_truths(_walls())
    assert south.facade_area_m2 == pytest.approx(40.0)
    assert south.window_area_m2 == pytest.approx(3.0)
    assert south.wwr == pytest.approx(3.0 / 40.0)
    assert north.door_area_m2 == pytest.approx(2.1) and north.window_area_m2 == 0.0
    assert east.width_m == pytest.approx(6.0) and east.height_m == 5.0
    assert south.normal == (0.0, -1.0, 0.0) and east.normal == (1.0, 0.0, 0.0)
    assert not south.curved


def test_curved_facade_groups_walls_and_averages_normals():
    ring = np.array([[0.0, 0.0], [2.0, 0.0], [3.0, 1.0], [3.0, 3.0], [0.0, 3.0]])
    walls = prism_walls(ring, 3.0, [1, 2, 2, 3, 4])
    f = facade_truths(walls, frozenset({2}))[1]
    assert f.curved and f.width_m == pytest.approx(np.sqrt(2) + 2.0)
    n = np.array([1.0, -1.0]) + 2.0 * np.array([1.0, 0.0])  # length-weighted: (3, -1)
    np.testing.assert_allclose(f.normal[:2], n / np.linalg.norm(n), atol=1e-12)


def test_outlines_give_the_world_corners():
    outlines = facade_outlines_m(_walls())
    assert outlines["1"] == [[[-4.0, -3.0, 0.0], [4.0, -3.0, 0.0], [4.0, -3.0, 5.0],
                              [-4.0, -3.0, 5.0]]]


def test_assembled_building_agrees_with_its_mesh():
    roof = parapet_roof_faces(RECT, 4.0, 1.0, 0.3)
    layout = BuildingLayout(RECT, _walls(), [ground_face(RECT), *roof], floors=1, height_m=5.0)
    building = assemble_layout(layout, building_id="box", building_type="skyscraper", seed=None)
    check_building(building)
    assert building.truth.footprint_area_m2 == pytest.approx(48.0)
    assert building.truth.facade_area_m2 == pytest.approx(2 * (8 + 6) * 5.0)


def test_bad_input_raises():
    walls = _walls()
    with pytest.raises(ValueError, match="without gaps"):
        facade_truths([walls[0], walls[2]])
    with pytest.raises(ValueError, match="floors >= 1"):
        assemble_building(building_id="b", building_type="skyscraper", seed=0, floors=0,
                          height_m=5.0, footprint_xy=RECT, walls=walls, other_faces=[])
