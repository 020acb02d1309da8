"""The per-orientation table of :mod:`metrics.score.orientation_errors`' summaries."""

from __future__ import annotations

from collections.abc import Sequence

from metrics.report.tables import Table
from metrics.score.orientation_errors import ORIENTATION_TABLE_NAME, OrientationSummary


def orientation_table(summaries: Sequence[OrientationSummary]) -> Table:
    """The per-orientation table: |WWR error| and bias (pp, mean ± std over buildings) and
    the share of facades within ±5 / ±10 pp, per family, method, views and bin."""
    return Table(
        name=ORIENTATION_TABLE_NAME,
        title="WWR error per orientation (percentage points), mean ± std over buildings, and "
              "share of facades within ±5 / ±10 points",
        columns=("Family", "Method", "Views", "Orientation", "Buildings", "Facades",
                 "|WWR error| (pp)", "Bias (pp)", "Within ±5 pp (%)", "Within ±10 pp (%)"),
        keys=("family", "method", "protocol", "orientation", "buildings", "facades",
              "abs_error_pp", "bias_pp", "within_5pp_percent", "within_10pp_percent"),
        rows=tuple((s.family, s.method, s.protocol, s.orientation, s.buildings, s.facades,
                    s.abs_error_pp, s.bias_pp, s.within_5pp_percent, s.within_10pp_percent)
                   for s in summaries),
        notes=("orientation: the truth facades' outward azimuth, EnergyPlus bins N [315, 45), "
               "E [45, 135), S [135, 225), W [225, 315); error = estimated - true WWR of the "
               "bin's facades; a facade not estimated counts as outside ±5 / ±10 pp",),
        decimals=2,
    )
