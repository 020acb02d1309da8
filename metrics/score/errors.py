"""Error measures of one method's estimate against the exact ground truth.

The paper's error is the absolute percentage error, ``100 * |est - true| / true``,
applied to the WWR (the paper's "mean absolute percentage error" once averaged),
to the window area ("window" error) and to the gross facade area ("wall" error).
Footprints are compared by intersection over union of their polygons. Where the truth
records the facade seen straight on (:meth:`envelope.truth.BuildingTruth.visible_areas_m2`),
the same errors are also taken against it (``*_ape_visible``): a method that measures what it
sees is not charged for wall hidden behind a railing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Literal

import shapely
from shapely.geometry import MultiPolygon, Polygon
from shapely.ops import unary_union

from envelope.footprint import geojson_to_polygon
from envelope.results import MethodResult
from envelope.truth import BuildingTruth
from metrics.score.facade_scoring import pair_facades, score_result

Status = Literal["ok", "failed"]
FacadeKind = Literal["matched", "missed", "false_positive"]
CUT_SHORT = "cut short"  # mark: a safety time cap stopped the run before its step budget
STALE = "stale"  # mark: made by other code or settings, kept with --reuse-stale
NO_TRUTH_FAMILY = "unknown"  # family of a scene without building.json (a user's photos)
LEFT_OUT_FACADE_ID = 0  # facade id of a row for an estimate on no truth facade (false positive)


def absolute_percentage_error(estimate: float, truth: float) -> float:
    """Absolute percentage error ``100 * |estimate - truth| / truth`` (in %).

    Raises
    ------
    ValueError
        If ``truth`` is not positive or either value is not finite.
    """
    if not (math.isfinite(estimate) and math.isfinite(truth)):
        raise ValueError(f"estimate {estimate} and truth {truth} must both be finite numbers")
    if truth <= 0:
        raise ValueError(
            f"the percentage error needs a positive true value, got {truth}; "
            "a building without windows has no WWR percentage error"
        )
    return 100.0 * abs(float(estimate) - float(truth)) / float(truth)


def footprint_iou(a: Polygon | MultiPolygon, b: Polygon | MultiPolygon) -> float:
    """Intersection over union of two footprint polygons (same frame and units), in [0, 1].

    Raises
    ------
    ValueError
        If either polygon has no area (an empty union has no IoU).
    """
    checked = []
    for name, poly in (("first", a), ("second", b)):
        if not isinstance(poly, Polygon | MultiPolygon):
            raise ValueError(f"{name} footprint must be a shapely (Multi)Polygon, got {type(poly)}")
        poly = _valid(poly)
        if poly.is_empty or poly.area <= 0:
            raise ValueError(f"{name} footprint has no area; cannot compute an IoU")
        checked.append(poly)
    a, b = checked
    union = a.union(b).area
    return float(a.intersection(b).area / union)


@dataclass(frozen=True)
class BuildingErrors:
    """One (scene, method, protocol): estimates, truth and errors (APE in %, IoU in [0, 1]).

    ``status`` is ``"failed"`` when the method produced no WWR (``reason`` says why);
    error fields are ``None`` where the method or the truth lacks the figure.
    ``steps`` is the training-step budget a method ran (``None`` for methods
    without one); ``marks`` lists what a reader must know about the figure
    (:data:`CUT_SHORT`, :data:`STALE`), joined by ``"; "``. Timing is kept
    apart (:class:`RunTiming`), so these rows are the same on every rerun.
    ``seed``: the training seed of a method trained from random weights (``None``:
    not one); several rows of one (scene, method, protocol) differ by it.
    ``*_ape_visible``: the errors against the facade seen straight on (``None`` where
    the truth lacks it).
    """

    scene: str
    family: str
    method: str
    protocol: str
    status: Status = "ok"
    reason: str = ""
    wwr_est: float | None = None
    wwr_true: float | None = None
    wwr_ape: float | None = None
    window_est_m2: float | None = None
    window_true_m2: float | None = None
    window_ape: float | None = None
    facade_est_m2: float | None = None
    facade_true_m2: float | None = None
    facade_ape: float | None = None
    footprint_iou: float | None = None
    steps: int | None = None
    marks: str = ""
    seed: int | None = None
    wwr_ape_visible: float | None = None
    window_ape_visible: float | None = None
    facade_ape_visible: float | None = None


@dataclass(frozen=True)
class RunTiming:
    """How long one (scene, method, protocol) took and whether it ran now or was reused."""

    scene: str
    method: str
    protocol: str
    status: str
    steps: int | None
    wall_time_s: float | None


@dataclass(frozen=True)
class FacadeErrors:
    """One facade of one (scene, method, protocol); APE in %, ``None`` where not estimated.

    ``kind`` (:mod:`metrics.score.facade_scoring`): ``"matched"``, a truth facade with an estimate;
    ``"missed"``, a truth facade without one (``status`` failed); ``"false_positive"``, an
    estimate on no wall of the truth (facade id :data:`LEFT_OUT_FACADE_ID`, ``status``
    failed, its estimate's ``facade_est_m2``). ``wwr_est``/``wwr_true`` are fractions; the
    error in WWR points is ``100 * |wwr_est - wwr_true|`` (:attr:`wwr_points`).
    """

    scene: str
    family: str
    method: str
    protocol: str
    facade_id: int
    status: Status = "ok"
    reason: str = ""
    wwr_est: float | None = None
    wwr_true: float | None = None
    wwr_ape: float | None = None
    window_ape: float | None = None
    facade_ape: float | None = None
    kind: FacadeKind = "matched"
    facade_est_m2: float | None = None

    @property
    def wwr_points(self) -> float | None:
        """Absolute WWR error in percentage points; ``None`` without both WWRs."""
        if self.wwr_est is None or self.wwr_true is None:
            return None
        return 100.0 * abs(self.wwr_est - self.wwr_true)


def failed_building(
    scene: str, family: str, method: str, protocol: str, reason: str
) -> BuildingErrors:
    """The row of a run that produced no usable result (crash, corrupt file, no views)."""
    return BuildingErrors(scene, family, method, protocol, status="failed", reason=reason)


def result_marks(result: MethodResult, *, stale: bool = False) -> str:
    """The marks of a result's row: :data:`CUT_SHORT` and/or :data:`STALE`, ``"; "``-joined."""
    return "; ".join(m for m, on in ((CUT_SHORT, result.cut_short), (STALE, stale)) if on)


def building_errors(
    result: MethodResult, truth: BuildingTruth | None, *, stale: bool = False
) -> BuildingErrors:
    """Errors of one result against its building's truth (``None``: estimates only).

    ``stale``: the result was kept although made by other code or settings.
    The building figures are the ones the scoring rule charges (:mod:`metrics.score.facade_scoring`:
    what lies on walls the truth does not count is left out, false positives count), and
    the reason says what was left out. A result without a WWR counts as failed, with its warnings
    as the reason. A footprint that cannot be compared (malformed GeoJSON) gives IoU ``None``
    and a reason, but does not fail the WWR figures.
    """
    family = truth.type if truth is not None else NO_TRUTH_FAMILY
    marks = result_marks(result, stale=stale)
    if truth is not None:
        scored = score_result(result, truth)
        result, covered_note = scored.result, scored.note
    else:
        covered_note = ""
    if result.wwr is None or not math.isfinite(result.wwr):
        reason = "; ".join(result.warnings) or "the method produced no WWR"
        return replace(failed_building(result.scene, family, result.method, result.protocol,
                                       reason), steps=result.steps, marks=marks, seed=result.seed)
    reasons: list[str] = [covered_note] if covered_note else []
    iou = None
    if result.footprint is not None and truth is not None:
        try:
            iou = footprint_iou(
                geojson_to_polygon(result.footprint), geojson_to_polygon(truth.footprint)
            )
        except ValueError as exc:
            reasons.append(f"footprint: {exc}")
    t = truth
    wwr_ape = _ape_or_none(result.wwr, t.wwr if t else None, reasons, "WWR")
    window_ape = _ape_or_none(
        result.window_area_m2, t.window_area_m2 if t else None, reasons, "window"
    )
    facade_ape = _ape_or_none(
        result.facade_area_m2, t.facade_area_m2 if t else None, reasons, "facade"
    )
    return BuildingErrors(
        scene=result.scene,
        family=family,
        method=result.method,
        protocol=result.protocol,
        reason="; ".join(reasons),
        wwr_est=result.wwr,
        wwr_true=t.wwr if t else None,
        wwr_ape=wwr_ape,
        window_est_m2=result.window_area_m2,
        window_true_m2=t.window_area_m2 if t else None,
        window_ape=window_ape,
        facade_est_m2=result.facade_area_m2,
        facade_true_m2=t.facade_area_m2 if t else None,
        facade_ape=facade_ape,
        footprint_iou=iou,
        steps=result.steps,
        marks=marks,
        seed=result.seed,
        **visible_errors(result, truth),
    )


def visible_errors(result: MethodResult, truth: BuildingTruth | None) -> dict[str, float | None]:
    """``wwr_ape_visible``, ``window_ape_visible``, ``facade_ape_visible``: the result's
    errors against the facade seen straight on (all ``None`` where the truth lacks it)."""
    visible = truth.visible_areas_m2() if truth is not None else None
    if visible is None:
        return {"wwr_ape_visible": None, "window_ape_visible": None, "facade_ape_visible": None}
    notes: list[str] = []  # a truth without visible windows has no percentage error: None
    return {
        "wwr_ape_visible": _ape_or_none(result.wwr, visible.wwr, notes, "WWR"),
        "window_ape_visible": _ape_or_none(result.window_area_m2, visible.window_m2, notes,
                                           "window"),
        "facade_ape_visible": _ape_or_none(result.facade_area_m2, visible.gross_m2, notes,
                                           "facade"),
    }


def facade_errors(result: MethodResult, truth: BuildingTruth | None) -> tuple[FacadeErrors, ...]:
    """Per-facade rows of a result under the one scoring rule (:mod:`metrics.score.facade_scoring`):
    one per truth facade (matched or missed) and one per false-positive estimate; every truth
    facade missed for a failed run (no WWR, no facades); none where there is no truth or the
    result's facades cannot be paired (own ids without locations). A malformed result file
    fails its facades, not the run.
    """
    if truth is None:
        return ()
    base = (result.scene, truth.type, result.method, result.protocol)
    if result.wwr is None and not result.facades:  # a failed run estimated no facade
        return missed_facades(result.scene, result.method, result.protocol, truth,
                              "; ".join(result.warnings) or "the method produced no WWR")
    try:
        match = pair_facades(result, truth)
    except ValueError as exc:
        return (FacadeErrors(*base, LEFT_OUT_FACADE_ID, status="failed", reason=str(exc),
                             kind="false_positive"),)
    if match is None:
        return ()
    true_by_id = {f.id: f for f in truth.facades}
    rows = []
    for est in match.facades:
        true = true_by_id[est.id]
        if est.missing or est.wwr is None:
            rows.append(FacadeErrors(*base, est.id, status="failed", wwr_true=true.wwr,
                                     reason=est.reason or "missing", kind="missed"))
            continue
        notes: list[str] = []
        wwr_ape = _ape_or_none(est.wwr, true.wwr, notes, "WWR")
        window_ape = _ape_or_none(est.window_area_m2, true.window_area_m2, notes, "window")
        facade_ape = _ape_or_none(est.facade_area_m2, true.facade_area_m2, notes, "facade")
        rows.append(FacadeErrors(
            *base, est.id, reason="; ".join(notes), wwr_est=est.wwr, wwr_true=true.wwr,
            wwr_ape=wwr_ape, window_ape=window_ape, facade_ape=facade_ape,
            facade_est_m2=est.facade_area_m2,
        ))
    rows.extend(FacadeErrors(*base, LEFT_OUT_FACADE_ID, status="failed", reason=u.reason,
                             wwr_est=u.estimate.wwr, kind="false_positive",
                             facade_est_m2=u.estimate.facade_area_m2)
                for u in match.false_positives)
    return tuple(rows)


def missed_facades(scene: str, method: str, protocol: str, truth: BuildingTruth | None,
                   reason: str) -> tuple[FacadeErrors, ...]:
    """Per-facade rows of a run that estimated no facade (it failed, or left no result
    file): every truth facade missed, with ``reason``; none without a truth."""
    if truth is None:
        return ()
    return tuple(FacadeErrors(scene, truth.type, method, protocol, f.id, status="failed",
                              reason=reason, wwr_true=f.wwr, kind="missed")
                 for f in truth.facades)


def _ape_or_none(
    estimate: float | None, truth: float | None, reasons: list[str], what: str
) -> float | None:
    if estimate is None or truth is None:
        return None
    try:
        return absolute_percentage_error(estimate, truth)
    except ValueError as exc:
        reasons.append(f"{what}: {exc}")
        return None


def _valid(poly: Polygon | MultiPolygon) -> Polygon | MultiPolygon:
    """The polygon itself if valid, else its repair (a bow-tie ring becomes two triangles)."""
    if poly.is_valid:
        return poly
    # make_valid keeps every lobe (buffer(0) can drop one) but may add lines: keep the areas.
    repaired = shapely.make_valid(poly)
    parts = [g for g in getattr(repaired, "geoms", [repaired]) if isinstance(g, Polygon)]
    parts += [p for g in getattr(repaired, "geoms", []) if isinstance(g, MultiPolygon)
              for p in g.geoms]
    return unary_union(parts) if parts else Polygon()
