"""WWR error per orientation (N, E, S, W): what an energy modeller's input would be off by.

Per building, method and bin (the truth's facade azimuths, :mod:`envelope.orientation`):

- the bin's true WWR (the truth's facades of that bin, areas summed) and the
  method's (its estimates on those facades,
  :func:`metrics.score.facade_scoring.estimates_by_truth_facade`:
  window and gross areas summed; the plain mean of the facades' WWRs when an
  estimate has no areas); the error is ``100 * (estimate - truth)`` in
  percentage points (pp), signed;
- how many of the bin's facades the method estimated within ±5 and ±10 pp (a
  facade it did not estimate counts as outside).

Summaries pool buildings per (family, method, protocol, bin): mean ± std of the
absolute error and of the signed error (bias) over the buildings where the
method estimated the bin, and the share (%) of the bin's facades within ±5 / ±10 pp.
Errors are in points, not percent of the truth, because a bin's true WWR may be 0.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from envelope.orientation import ORIENTATION_BINS, OrientationBin
from envelope.results import MethodResult
from envelope.truth import BuildingTruth
from envelope.wwr import wwr_from_areas
from metrics.score.aggregate import (
    ALL_FAMILIES,
    Summary,
    family_rank,
    method_rank,
    protocol_rank,
    summarise,
)
from metrics.score.facade_scoring import estimates_by_truth_facade

WITHIN_PP = (5.0, 10.0)  # the two bands users asked for, in percentage points
_ROUNDING = 1e-9  # an error of exactly 5 pp counts as within 5 pp despite float round-off
ORIENTATION_TABLE_NAME = "table_orientation_wwr"


@dataclass(frozen=True)
class OrientationErrors:
    """One bin of one (scene, method, protocol); WWRs as fractions, errors in pp."""

    scene: str
    family: str
    method: str
    protocol: str
    orientation: OrientationBin
    facades: int
    estimated: int
    wwr_true: float | None
    wwr_est: float | None
    error_pp: float | None
    within_5pp: int
    within_10pp: int


@dataclass(frozen=True)
class OrientationSummary:
    """One (family, method, protocol, bin) pooled over its buildings (see module)."""

    family: str
    method: str
    protocol: str
    orientation: OrientationBin
    buildings: int
    facades: int
    abs_error_pp: Summary
    bias_pp: Summary
    within_5pp_percent: float | None
    within_10pp_percent: float | None


def orientation_errors(result: MethodResult, truth: BuildingTruth | None
                       ) -> tuple[OrientationErrors, ...]:
    """A row per bin the truth's facades face; none without truth or facades to compare."""
    if truth is None:
        return ()
    estimates = estimates_by_truth_facade(result, truth)
    if estimates is None:
        return ()
    est_by_id = {e.id: e for e in estimates}
    rows = []
    for b in ORIENTATION_BINS:
        facing = [f for f in truth.facades if f.orientation == b]
        if not facing:
            continue
        pairs = [(f, est_by_id.get(f.id)) for f in facing]
        known = [(f, e) for f, e in pairs if e is not None and not e.missing and e.wwr is not None]
        true = wwr_from_areas(sum(f.window_area_m2 for f in facing),
                              sum(f.wall_area_m2 for f in facing),
                              sum(f.door_area_m2 for f in facing))
        est = _bin_wwr([e for _, e in known])
        deviations = [abs(e.wwr - f.wwr) * 100.0 for f, e in known]
        rows.append(OrientationErrors(
            scene=result.scene, family=truth.type, method=result.method,
            protocol=result.protocol, orientation=b, facades=len(facing), estimated=len(known),
            wwr_true=true, wwr_est=est,
            error_pp=None if est is None or true is None else 100.0 * (est - true),
            within_5pp=sum(d <= WITHIN_PP[0] + _ROUNDING for d in deviations),
            within_10pp=sum(d <= WITHIN_PP[1] + _ROUNDING for d in deviations)))
    return tuple(rows)


def summarise_orientations(rows: Sequence[OrientationErrors], *, pooled: bool = True
                           ) -> tuple[OrientationSummary, ...]:
    """One summary per (family, method, protocol, bin); with ``pooled`` also per (method,
    protocol, bin) over all families (family :data:`metrics.score.aggregate.ALL_FAMILIES`)."""
    keys = {(r.family, r.method, r.protocol, r.orientation) for r in rows}
    if pooled:
        keys |= {(ALL_FAMILIES, r.method, r.protocol, r.orientation) for r in rows}
    out = []
    for family, method, protocol, b in sorted(keys, key=_order):
        members = [r for r in rows if (r.method, r.protocol, r.orientation) == (method,
                   protocol, b) and family in (ALL_FAMILIES, r.family)]
        errors = [r.error_pp for r in members if r.error_pp is not None]
        facades = sum(r.facades for r in members)
        out.append(OrientationSummary(
            family=family, method=method, protocol=protocol, orientation=b,
            buildings=len(members), facades=facades,
            abs_error_pp=summarise(abs(e) for e in errors), bias_pp=summarise(errors),
            within_5pp_percent=_share(sum(r.within_5pp for r in members), facades),
            within_10pp_percent=_share(sum(r.within_10pp for r in members), facades)))
    return tuple(out)


def orientation_errors_of(pairs: Iterable[tuple[MethodResult, BuildingTruth | None]]
                          ) -> list[OrientationErrors]:
    """:func:`orientation_errors` of every (result, truth) pair, in order."""
    return [row for result, truth in pairs for row in orientation_errors(result, truth)]


def _bin_wwr(estimates) -> float | None:
    if not estimates:
        return None
    if all(e.window_area_m2 is not None and e.facade_area_m2 is not None for e in estimates):
        window = sum(e.window_area_m2 for e in estimates)
        gross = sum(e.facade_area_m2 for e in estimates)
        return wwr_from_areas(window, max(gross - window, 0.0), 0.0)
    return sum(e.wwr for e in estimates) / len(estimates)


def _share(count: int, total: int) -> float | None:
    return None if total == 0 else 100.0 * count / total


def _order(key: tuple[str, str, str, str]) -> tuple:
    family, method, protocol, b = key
    return (family_rank(family), method_rank(method), protocol_rank(protocol),
            ORIENTATION_BINS.index(b))
