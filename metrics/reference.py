"""Reference figures the report shows beside ours: the paper preset's Table 2 of the 2D methods.

These are the errors of 2D-S and 2D-SS on the full ``paper`` preset (28
buildings, 512 px images; result files made at commit 787c3dfe2b9d, see
docs/baselines.md), absolute percentage error in %, mean and population std
over buildings. The published paper's own tables are not recorded in this
project; no footprint (Table 3) reference exists, as the 2D methods estimate none.
"""

from __future__ import annotations

from dataset.core.protocols import IDEAL_PROTOCOL as IDEAL
from dataset.core.protocols import MULTI_PROTOCOL as MULTI
from metrics.aggregate import Summary

REFERENCE_LABEL = "paper preset (28 buildings, 512 px, commit 787c3dfe2b9d)"
REFERENCE_KEYS = ("wwr_ape", "window_ape", "facade_ape")

# (family, method, views) -> (WWR, window, facade) errors as (mean, std), in %.
_TABLE2: dict[tuple[str, str, str], tuple[tuple[float, float], ...]] = {
    ("skyscraper", "2D-S", IDEAL): ((1.49, 1.53), (1.40, 0.74), (0.43, 0.25)),
    ("skyscraper", "2D-S", MULTI): ((0.63, 0.54), (16.42, 2.47), (16.70, 2.35)),
    ("skyscraper", "2D-SS", IDEAL): ((1.38, 1.14), (1.40, 0.75), (0.42, 0.24)),
    ("skyscraper", "2D-SS", MULTI): ((0.44, 0.35), (0.38, 0.31), (0.31, 0.08)),
    ("l_shaped", "2D-S", IDEAL): ((1.06, 1.11), (17.48, 4.88), (17.32, 5.20)),
    ("l_shaped", "2D-S", MULTI): ((2.33, 1.41), (15.38, 5.66), (16.49, 5.41)),
    ("l_shaped", "2D-SS", IDEAL): ((0.48, 0.32), (0.39, 0.32), (0.12, 0.08)),
    ("l_shaped", "2D-SS", MULTI): ((0.40, 0.31), (0.58, 0.39), (0.80, 0.31)),
    ("realistic", "2D-S", IDEAL): ((7.70, 6.82), (13.89, 13.53), (8.56, 7.78)),
    ("realistic", "2D-S", MULTI): ((10.48, 9.13), (16.76, 15.19), (8.78, 7.21)),
    ("realistic", "2D-SS", IDEAL): ((9.83, 4.42), (14.29, 9.20), (10.10, 9.82)),
    ("realistic", "2D-SS", MULTI): ((11.81, 6.83), (16.73, 6.38), (10.13, 9.56)),
    ("all", "2D-S", IDEAL): ((2.19, 3.64), (10.08, 9.72), (8.83, 9.02)),
    ("all", "2D-S", MULTI): ((2.77, 4.84), (16.02, 7.05), (15.48, 5.46)),
    ("all", "2D-SS", IDEAL): ((2.20, 3.64), (2.81, 5.88), (1.67, 5.07)),
    ("all", "2D-SS", MULTI): ((2.05, 4.76), (2.80, 6.19), (1.92, 4.94)),
}
_PAPER_BUILDINGS = {"skyscraper": 12, "l_shaped": 12, "realistic": 4, "all": 28}


def reference_table2(family: str, method: str, protocol: str) -> dict[str, Summary] | None:
    """The reference errors of one Table 2 row by key of :data:`REFERENCE_KEYS`, or ``None``."""
    row = _TABLE2.get((family, method, protocol))
    if row is None:
        return None
    count = _PAPER_BUILDINGS[family]
    return {k: Summary(mean, std, count) for k, (mean, std) in zip(REFERENCE_KEYS, row)}
