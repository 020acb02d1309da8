"""The bootstrap interval of a mean: closed-form cases, determinism, refusals."""

import numpy as np
import pytest

from metrics.score.bootstrap import BOOTSTRAP_RESAMPLES, INTERVAL_TEXT, bootstrap_interval


def test_identical_values_have_an_interval_of_zero_width():
    low, high = bootstrap_interval([2.5, 2.5, 2.5, 2.5])
    assert low == high == pytest.approx(2.5, abs=1e-15)


def test_two_values_span_from_one_to_the_other():
    # Resample means of {a, b}: a, (a + b) / 2, b with chances 1/4, 1/2, 1/4, so the
    # 2.5th and 97.5th percentiles are a and b themselves.
    assert bootstrap_interval([1.0, 3.0]) == (1.0, 3.0)


def test_many_values_give_the_normal_interval_of_the_mean():
    x = np.arange(400.0)  # population std 115.47: the mean's is 5.77
    low, high = bootstrap_interval(x)
    half = 1.959964 * x.std() / np.sqrt(len(x))
    assert low == pytest.approx(x.mean() - half, abs=0.05 * half)
    assert high == pytest.approx(x.mean() + half, abs=0.05 * half)


def test_interval_is_deterministic_and_named():
    x = [0.5, 5.4, 3.8, 0.5]
    assert bootstrap_interval(x) == bootstrap_interval(list(x))
    assert bootstrap_interval(x, seed=1) != bootstrap_interval(x)
    assert "95% percentile bootstrap" in INTERVAL_TEXT
    assert f"{BOOTSTRAP_RESAMPLES:,}" in INTERVAL_TEXT


def test_one_value_has_no_interval_and_bad_input_raises():
    assert bootstrap_interval([1.0]) is None
    assert bootstrap_interval([]) is None
    with pytest.raises(ValueError, match="finite"):
        bootstrap_interval([1.0, float("nan")])
    with pytest.raises(ValueError, match="level"):
        bootstrap_interval([1.0, 2.0], level=1.5)
