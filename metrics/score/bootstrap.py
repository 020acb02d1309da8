"""Percentile bootstrap interval of a mean over buildings: deterministic, settings named once.

The tables' error bars: the buildings of a family are resampled with replacement
:data:`BOOTSTRAP_RESAMPLES` times (numpy's ``default_rng(BOOTSTRAP_SEED)``, so the
same values always give the same interval), the mean of each resample is taken,
and the interval is the central :data:`BOOTSTRAP_LEVEL` of those means (percentiles
2.5 and 97.5, numpy's linear interpolation). It says how far the family mean could
move with other buildings of the same kind; with few buildings it is narrow by
construction (n = 4 spans at most the values seen) and says so only roughly.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

BOOTSTRAP_LEVEL = 0.95
BOOTSTRAP_RESAMPLES = 10_000
BOOTSTRAP_SEED = 0
INTERVAL_TEXT = (f"{BOOTSTRAP_LEVEL:.0%} percentile bootstrap interval of the mean over "
                 f"buildings ({BOOTSTRAP_RESAMPLES:,} resamples, seed {BOOTSTRAP_SEED})")
"""How the tables name the interval."""


def bootstrap_interval(
    values: Sequence[float], *, level: float = BOOTSTRAP_LEVEL,
    resamples: int = BOOTSTRAP_RESAMPLES, seed: int = BOOTSTRAP_SEED,
) -> tuple[float, float] | None:
    """(low, high) percentile bootstrap interval of the mean of ``values`` ((n,) floats).

    ``None`` for fewer than two values (one building has no spread to resample).

    Raises
    ------
    ValueError
        If ``level`` is not in (0, 1), ``resamples`` < 1 or a value is not finite.
    """
    x = np.asarray(values, dtype=np.float64)
    if not 0 < level < 1 or resamples < 1:
        raise ValueError(f"need 0 < level < 1 and resamples >= 1, got {level}, {resamples}")
    if x.ndim != 1 or not np.isfinite(x).all():
        raise ValueError(f"bootstrap needs a 1-D array of finite values, got {values!r}")
    if len(x) < 2:
        return None
    picks = np.random.default_rng(seed).integers(0, len(x), size=(resamples, len(x)))
    means = x[picks].mean(axis=1)
    tail = (1 - level) / 2 * 100
    low, high = np.percentile(means, [tail, 100 - tail])
    return float(low), float(high)
