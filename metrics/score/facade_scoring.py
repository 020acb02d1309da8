"""The one scoring rule: which of a result's facades count, and what its building is charged.

Every method is scored the same way (docs/metrics.md, "One scoring rule"):

- A result whose facade ids are the truth's (the ideal and multi views carry the id of the
  facade they were aimed at) is paired with the truth by id.
- A result that numbers its own facades and locates them (``normal`` and ``centre_m``) is
  matched with the truth's walls by geometry, covered or not
  (:func:`metrics.score.facade_match.match_facades`): each covered truth facade gets at most one
  estimate, an estimate on a wall the truth does not count (a CityGML model's backyard and
  party walls) is **out of scope**, and one on no wall of the truth is a **false positive**.
- A covered truth facade with no estimate is **missed**.

The building's figures are the result's own totals less what lies out of scope: a false
positive's areas stay in the sums (they are the method's error), a missed facade's are
absent from them. Against a truth that counts every wall (procedural and imported
buildings) nothing is out of scope, so the building figures are the result's own.

A result without per-facade figures, or one that numbers its own facades but does not locate
them, cannot be paired: its building totals stand as they are and it has no per-facade
scores.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from envelope.results import FacadeEstimate, MethodResult
from envelope.truth import BuildingTruth
from envelope.wwr import ClassAreas
from metrics.score.facade_match import FacadeMatch, Unmatched, has_facade_geometry, match_facades


@dataclass(frozen=True)
class ScoredResult:
    """A result under the rule: its figures in scope and how its facades met the truth.

    ``result``: the method's result with building figures less what lies out of scope
    (``wwr`` ``None`` where nothing is left). ``match``: the pairing (``None`` where the
    result's facades cannot be paired: none reported, or own ids without locations).
    ``note``: what a reader of the row must know (empty where nothing was left out).
    """

    result: MethodResult
    match: FacadeMatch | None
    note: str = ""


def pair_facades(result: MethodResult, truth: BuildingTruth) -> FacadeMatch | None:
    """The result's facades paired with the truth's (see the module docstring).

    Raises
    ------
    ValueError
        From :func:`metrics.score.facade_match.match_facades` for a malformed estimate (no or a
        zero normal) or a truth whose uncovered walls have no outlines (an old scene).
    """
    if not result.facades:
        return None
    if result.facade_identity == "truth_id":
        by_id = {e.id: e for e in result.facades}
        known = {t.id for t in truth.facades}
        facades = tuple(by_id.get(t.id) or FacadeEstimate(
            id=t.id, wwr=None, missing=True, reason="no estimate for this facade")
            for t in truth.facades)
        strays = tuple(Unmatched(e, f"estimated facade {e.id}: no such facade in the truth")
                       for e in result.facades if e.id not in known)
        return FacadeMatch(facades, (), strays)
    if has_facade_geometry(result.facades):
        return match_facades(result.facades, truth)
    return None


def score_result(result: MethodResult, truth: BuildingTruth) -> ScoredResult:
    """``result`` under the one rule against ``truth`` (see the module docstring).

    A malformed result file (a zero normal) or an old scene fails the figures with the
    reason among the result's warnings rather than the comparison.
    """
    try:
        match = pair_facades(result, truth)
    except ValueError as exc:
        return ScoredResult(_without_figures(result, str(exc)), None)
    if match is None or not match.out_of_scope or result.wwr is None:
        return ScoredResult(result, match, _note(match))
    left = [u.estimate for u in match.out_of_scope]
    if any(e.window_area_m2 is None or e.facade_area_m2 is None for e in left):
        return ScoredResult(_without_figures(
            result, "an estimated facade on a wall the truth does not count has no areas to "
                    "take out of the building's figures"), match, _note(match))
    window_m2 = (result.window_area_m2 or 0.0) - sum(e.window_area_m2 for e in left)
    gross_m2 = (result.facade_area_m2 or 0.0) - sum(e.facade_area_m2 for e in left)
    if gross_m2 <= 1e-9:
        return ScoredResult(_without_figures(
            result, "every estimated facade lies on walls the truth does not count"),
            match, _note(match))
    window_m2 = min(max(window_m2, 0.0), gross_m2)
    areas = ClassAreas(window_m2, gross_m2 - window_m2, 0.0)
    return ScoredResult(replace(result, wwr=areas.wwr, window_area_m2=window_m2,
                                facade_area_m2=gross_m2), match, _note(match))


def facade_area_m2(unmatched: tuple[Unmatched, ...]) -> float:
    """Total facade area (m²) of some estimates (an estimate without one adds 0)."""
    return float(sum(u.estimate.facade_area_m2 or 0.0 for u in unmatched))


def _note(match: FacadeMatch | None) -> str:
    if match is None or not (match.out_of_scope or match.false_positives):
        return ""
    parts = []
    if match.out_of_scope:
        parts.append(f"{len(match.out_of_scope)} estimated facades "
                     f"({facade_area_m2(match.out_of_scope):.1f} m²) on walls the truth does "
                     "not count, left out")
    if match.false_positives:
        parts.append(f"{len(match.false_positives)} false-positive facades "
                     f"({facade_area_m2(match.false_positives):.1f} m²), counted")
    return "; ".join(parts)


def _without_figures(result: MethodResult, reason: str) -> MethodResult:
    return replace(result, wwr=None, window_area_m2=None, facade_area_m2=None,
                   warnings=(*result.warnings, reason))


def estimates_by_truth_facade(result: MethodResult, truth: BuildingTruth
                              ) -> tuple[FacadeEstimate, ...] | None:
    """The result's figures on the truth's facade ids (one per truth facade, in its order),
    paired by the one scoring rule (:func:`metrics.score.facade_scoring.pair_facades`).

    ``None`` when the result has no per-facade figures, cannot be paired or the pairing fails.
    """
    if not result.facades:
        return None
    try:
        match = pair_facades(result, truth)
    except ValueError:
        return None
    return None if match is None else match.facades
