"""A building's figures over the facades its truth counts, where that is not every wall.

A CityGML LoD3 model of a street is complete only where the scanner saw it: its truth
counts the *covered* facades (a window or door modelled on them) and lists the others
(backyard and party walls) apart (``extra["uncovered_facades"]``, docs/importing.md
section 8). The building's true WWR is the covered facades' WWR.

The 2D methods measure the facades they have views of, which are the truth's, so their
building figures are already over the covered facades. A method that finds its own
facades (neural3d: every wall it reconstructs) would be charged for walls the truth does
not count. Against such a truth its building figures are therefore taken over its located
facades that lie on a covered facade (:func:`metrics.facade_match.match_facades` with
``max_distance_m`` = :data:`ON_FACADE_MAX_DISTANCE_M`): window and facade areas add up and
the WWR is their ratio (:class:`dataset.core.wwr.ClassAreas`). Against a truth that counts
every wall (the procedural and imported buildings) nothing changes.

The limit was chosen on the paper preset's buildings (the set settings are chosen on,
docs/decisions.md): neural3d's facade centres there lie 0.00-0.10 m from their facade's
wall outline (6 runs on 4 buildings, 28 facades); 1 m leaves ten times that, and is less than the
depth of a bay or a balcony, so a party wall beside a narrow bay side does not join it.
"""

from __future__ import annotations

from dataclasses import replace

from dataset.core.results import MethodResult
from dataset.core.truth import BuildingTruth
from dataset.core.wwr import ClassAreas
from metrics.facade_match import has_facade_geometry, match_facades

ON_FACADE_MAX_DISTANCE_M = 1.0  # an estimated facade's centre within this of a covered wall


def counts_every_wall(truth: BuildingTruth) -> bool:
    """Whether the truth's facades are all of the building's walls (``False``: a CityGML
    model whose uncovered walls are listed apart)."""
    return not truth.extra.get("uncovered_facades")


def facade_distance_limit_m(truth: BuildingTruth) -> float | None:
    """The ``max_distance_m`` to match a result's own facades to ``truth`` with:
    :data:`ON_FACADE_MAX_DISTANCE_M` where the truth counts only some walls, else ``None``."""
    return None if counts_every_wall(truth) else ON_FACADE_MAX_DISTANCE_M


def over_truth_facades(result: MethodResult, truth: BuildingTruth) -> tuple[MethodResult, str]:
    """``result`` with its building figures taken over its facades on the truth's facades,
    and a note saying so; ``(result, "")`` where nothing changes (a truth that counts every
    wall, a result whose facade ids are the truth's or that does not locate its facades, a
    failed result).

    The note names how many estimated facades counted and how many were left out.
    """
    limit_m = facade_distance_limit_m(truth)
    if (limit_m is None or result.facade_identity == "truth_id"
            or result.wwr is None or not has_facade_geometry(result.facades)):
        return result, ""
    try:
        match = match_facades(result.facades, truth, max_distance_m=limit_m)
    except ValueError as exc:  # a malformed result file (a zero normal) fails its figures
        return replace(result, wwr=None, window_area_m2=None, facade_area_m2=None,
                       warnings=(*result.warnings, str(exc))), ""
    on = [f for f in match.facades if not f.missing and f.window_area_m2 is not None
          and f.facade_area_m2 is not None]
    window_m2 = sum(f.window_area_m2 for f in on)
    gross_m2 = sum(f.facade_area_m2 for f in on)
    note = (f"over the covered facades: {len(on)} of {len(match.facades)} reached, "
            f"{len(match.left_out)} estimated facades on walls the truth does not count")
    if not on or gross_m2 <= 0:
        return replace(result, wwr=None, window_area_m2=None, facade_area_m2=None,
                       warnings=(*result.warnings, "no estimated facade lies on a covered "
                                 "facade of the truth")), note
    areas = ClassAreas(window_m2, max(gross_m2 - window_m2, 0.0), 0.0)
    return replace(result, wwr=areas.wwr, window_area_m2=window_m2,
                   facade_area_m2=gross_m2), note
