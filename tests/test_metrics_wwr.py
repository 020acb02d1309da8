"""The project's one WWR definition (metrics.wwr): window / (wall + window + door)."""

import pytest

from metrics.wwr import gross_facade_area_m2, window_to_wall_ratio


def test_gross_facade_area_is_wall_plus_window_plus_door():
    assert gross_facade_area_m2(30.0, 10.0, 2.0) == 42.0
    assert gross_facade_area_m2(0.0, 0.0, 0.0) == 0.0


def test_wwr_closed_form():
    # A 10 m x 3 m facade with two 1.5 m x 1.2 m windows: 3.6 / 30 = 0.12 exactly.
    window = 2 * 1.5 * 1.2
    gross = gross_facade_area_m2(30.0 - window - 2.0, window, 2.0)
    assert window_to_wall_ratio(window, gross) == pytest.approx(0.12, abs=1e-15)
    assert window_to_wall_ratio(0.0, 5.0) == 0.0
    assert window_to_wall_ratio(5.0, 5.0) == 1.0


def test_wwr_clamps_rounding_noise_to_one():
    assert window_to_wall_ratio(5.0 + 1e-12, 5.0) == 1.0


@pytest.mark.parametrize(
    ("window", "gross", "message"),
    [(1.0, 0.0, "must be > 0"), (1.0, -2.0, "must be > 0"), (-1.0, 2.0, "must be >= 0"),
     (3.0, 2.0, "exceeds gross facade area")],
)
def test_wwr_bad_input(window, gross, message):
    with pytest.raises(ValueError, match=message):
        window_to_wall_ratio(window, gross)


def test_gross_area_rejects_negative_parts():
    with pytest.raises(ValueError, match="door area must be >= 0"):
        gross_facade_area_m2(1.0, 1.0, -0.5)
