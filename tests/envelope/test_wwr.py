"""The project's one WWR definition (envelope.wwr): window / (wall + window + door)."""

from dataclasses import FrozenInstanceError

import numpy as np
import pytest

from envelope.wwr import ClassAreas, wwr_from_areas


def test_gross_facade_area_is_wall_plus_window_plus_door():
    assert ClassAreas(window_m2=10.0, wall_m2=30.0, door_m2=2.0).gross_m2 == 42.0
    assert ClassAreas(0.0, 0.0, 0.0).gross_m2 == 0.0


def test_class_areas_wwr_is_the_one_ratio():
    # A 10 m x 3 m facade with two 1.5 m x 1.2 m windows and a 2 m² door: 3.6 / 30 = 0.12.
    window = 2 * 1.5 * 1.2
    areas = ClassAreas(window_m2=window, wall_m2=30.0 - window - 2.0, door_m2=2.0)
    assert areas.wwr == pytest.approx(0.12, abs=1e-15)
    assert areas.wwr == wwr_from_areas(window, 30.0 - window - 2.0, 2.0)
    assert ClassAreas(0.0, 0.0, 0.0).wwr is None
    assert ClassAreas(5.0, 0.0, 0.0).wwr == 1.0


def test_class_areas_are_plain_frozen_floats():
    areas = ClassAreas(np.float32(1.5), 2, np.float64(0.5))
    assert [type(a) for a in (areas.window_m2, areas.wall_m2, areas.door_m2)] == [float] * 3
    with pytest.raises(FrozenInstanceError):
        areas.window_m2 = 2.0


def test_wwr_closed_form_doors_count_in_the_denominator():
    # Without the door in the denominator it would be 3.6 / 28.
    assert wwr_from_areas(3.6, 24.4, 2.0) != pytest.approx(3.6 / 28.0)


def test_wwr_no_window_no_facade_all_window():
    assert wwr_from_areas(0.0, 5.0, 0.0) == 0.0
    assert wwr_from_areas(5.0, 0.0, 0.0) == 1.0
    assert wwr_from_areas(0.0, 0.0, 0.0) is None  # no facade: no WWR
    assert wwr_from_areas(0.0, 0.0, 1.0) == 0.0  # a door alone is facade without window


def test_wwr_of_arrays_broadcasts_with_nan_where_no_facade():
    out = wwr_from_areas(np.array([1, 0, 2]), np.array([3, 0, 0]), 0)
    np.testing.assert_array_equal(out, [0.25, np.nan, 1.0])


@pytest.mark.parametrize("areas", [(-1.0, 2.0, 0.0), (1.0, -2.0, 0.0), (1.0, 2.0, np.nan),
                                   (np.inf, 1.0, 0.0)])
def test_wwr_bad_input(areas):
    with pytest.raises(ValueError, match="must be finite and >= 0"):
        wwr_from_areas(*areas)
    with pytest.raises(ValueError, match="must be finite and >= 0 m²"):
        ClassAreas(*areas)


def test_class_areas_name_the_bad_part():
    with pytest.raises(ValueError, match="door area must be finite and >= 0"):
        ClassAreas(1.0, 1.0, -0.5)
