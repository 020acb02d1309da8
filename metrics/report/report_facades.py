"""The facade scores table: how each method's facades met the truth under the one rule.

Per family, method and views (and over all families), from the per-facade rows of
:func:`metrics.score.errors.facade_errors` (:mod:`metrics.score.facade_scoring`):

- **coverage**: the share of the truth's (covered) facades that have an estimate;
- **false positives**: estimated facades on no wall of the truth, and their facade area (m²);
- **mean error**: the mean absolute WWR error in points (100 × |WWR_est − WWR_true|) over
  the facades with an estimate;
- **within ±5 / ±10 points**: the share of *all* the truth's facades estimated that well
  (a missed facade counts as outside both: the street-view papers' figure);
- **building WWR error**: Table 2's (%), beside them.

A failed run (no result, or no WWR) has missed every facade of its building. A result that
reports no per-facade figures, or numbers its own facades without locating them, has no
rows and does not count here (the ``Buildings`` column says how many did).
A building trained with several seeds counts once per seed.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Sequence

from metrics.report.tables import Cell, Table
from metrics.score.aggregate import (
    ALL_FAMILIES,
    GroupSummary,
    family_rank,
    method_rank,
    protocol_rank,
)
from metrics.score.errors import FacadeErrors

FACADE_SCORES_NAME = "facade_scores"
BANDS_POINTS = (5.0, 10.0)  # the street-view papers' bands (Suppa et al. 2025)


def facade_scores_table(rows: Sequence[FacadeErrors],
                        groups: Sequence[GroupSummary] = ()) -> Table:
    """The facade scores of ``rows`` per (family, method, protocol) and over all families,
    with each group's building WWR error from ``groups`` (Table 2's summaries)."""
    by_key: dict[tuple[str, str, str], list[FacadeErrors]] = defaultdict(list)
    for r in rows:
        by_key[(r.family, r.method, r.protocol)].append(r)
        by_key[(ALL_FAMILIES, r.method, r.protocol)].append(r)
    building_wwr = {(g.family, g.method, g.protocol): g.wwr_ape for g in groups}
    ordered = sorted(by_key, key=lambda k: (family_rank(k[0]), method_rank(k[1]),
                                            protocol_rank(k[2])))
    if len({k[0] for k in ordered}) == 2:  # one family: its "all" row says the same
        ordered = [k for k in ordered if k[0] == ALL_FAMILIES]
    return Table(
        name=FACADE_SCORES_NAME,
        title="Facades under the one scoring rule: coverage, false positives and WWR error "
              "in points",
        columns=("Family", "Method", "Views", "Buildings", "Facades", "Coverage (%)",
                 "False positives", "False-positive area (m²)", "Mean error (points)",
                 "Within ±5 (%)", "Within ±10 (%)", "Building WWR error (%)"),
        keys=("family", "method", "protocol", "buildings", "facades", "coverage_pct",
              "false_positives", "false_positive_m2", "mean_points", "within_5_pct",
              "within_10_pct", "wwr_ape"),
        rows=tuple(_row(k, by_key[k], building_wwr.get(k)) for k in ordered),
        notes=("coverage: truth facades with an estimate; within: share of all truth facades "
               "(a missed facade is outside); mean error over the facades with an estimate; "
               "false positives: estimates on no wall of the truth (their areas count in the "
               "building's figures); docs/metrics.md, \"One scoring rule\"",),
    )


def _row(key: tuple[str, str, str], rows: list[FacadeErrors], wwr_ape: Cell) -> tuple[Cell, ...]:
    truth_rows = [r for r in rows if r.kind != "false_positive"]
    matched = [r for r in truth_rows if r.kind == "matched"]
    points = [r.wwr_points for r in matched if r.wwr_points is not None]
    positives = [r for r in rows if r.kind == "false_positive"]
    within = tuple(_percent(sum(p <= band for p in points), len(truth_rows))
                   for band in BANDS_POINTS)
    return (*key, len({r.scene for r in rows}), len(truth_rows),
            _percent(len(matched), len(truth_rows)), len(positives),
            float(sum(r.facade_est_m2 or 0.0 for r in positives)),
            sum(points) / len(points) if points else None, *within, wwr_ape)


def _percent(part: int, whole: int) -> float | None:
    return 100.0 * part / whole if whole else None
