"""The estimates table: what each method measured of each building, with no truth beside it.

A comparison on scenes without ground truth (no ``building.json``: a user's photos,
``python -m dataset.generate --photos``) has nothing to score: it writes this table instead of
errors, one row per (scene, method, views, seed) of every scene, with the method's WWR,
window and facade areas (m²), footprint area (m², of its footprint polygon) and how many
facades it estimated. The per-facade and per-orientation figures are the energy exports'
(:mod:`metrics.export.table`). A folder mixing scenes with and without truth gets its errors
over the scenes with truth and this table over all of them (:func:`truth_note` says which).
"""

from __future__ import annotations

from collections.abc import Sequence

from envelope.footprint import geojson_to_polygon
from envelope.results import MethodResult
from metrics.report.tables import Cell, Table
from metrics.run.runner import Outcome
from metrics.score.errors import NO_TRUTH_FAMILY, BuildingErrors, result_marks

ESTIMATES_NAME = "estimates"
ESTIMATE_KEYS = ("scene", "method", "protocol", "seed", "status", "reason", "wwr", "window_m2",
                 "facade_m2", "footprint_m2", "facades", "steps", "marks")


def estimates_table(outcomes: Sequence[Outcome], without_truth: Sequence[str]) -> Table:
    """Every outcome's estimates (a failed run: its status and reason, no figures), noted
    with :func:`truth_note`."""
    return Table(
        name=ESTIMATES_NAME,
        title="Estimates per building (no errors: WWR a fraction, areas in m²)",
        columns=("Scene", "Method", "Views", "Seed", "Status", "Why", "WWR", "Window (m²)",
                 "Facade (m²)", "Footprint (m²)", "Facades", "Steps", "Marks"),
        keys=ESTIMATE_KEYS,
        rows=tuple(_row(o) for o in outcomes),
        notes=(truth_note(without_truth, len({o.scene for o in outcomes})),),
        decimals=4,
    )


def truth_note(without_truth: Sequence[str], scenes: int) -> str:
    """What can be scored: nothing (no scene has truth), or the scenes with truth only."""
    names = ", ".join(without_truth)
    if len(without_truth) >= scenes:
        return (f"no ground truth (building.json) in any scene ({names}): these are estimates, "
                "not measured against anything, so there are no errors")
    return (f"errors are over the {scenes - len(without_truth)} of {scenes} scenes with ground "
            f"truth (building.json); {names} have none: estimates only")


def estimate_rows(records: Sequence[dict[str, Cell]]) -> list[BuildingErrors]:
    """The estimates table's records as per-building rows without truth (family
    :data:`~metrics.score.errors.NO_TRUTH_FAMILY`), for the report's building sections."""
    return [BuildingErrors(
        scene=str(r["scene"]), family=NO_TRUTH_FAMILY, method=str(r["method"]),
        protocol=str(r["protocol"]), status="ok" if r["status"] == "ok" else "failed",
        reason=str(r["reason"] or ""), wwr_est=_float(r["wwr"]),
        window_est_m2=_float(r["window_m2"]), facade_est_m2=_float(r["facade_m2"]),
        steps=None if r["steps"] is None else int(r["steps"]), marks=str(r["marks"] or ""),
        seed=None if r["seed"] is None else int(r["seed"])) for r in records]


def _row(o: Outcome) -> tuple[Cell, ...]:
    r = o.result
    if r is None or r.wwr is None:
        why = o.reason if r is None else "; ".join(r.warnings) or "the method produced no WWR"
        return (o.scene, o.method, o.protocol, None if r is None else r.seed, "failed", why,
                None, None, None, None, None, None if r is None else r.steps,
                "" if r is None else result_marks(r, stale=o.status == "stale"))
    footprint_m2, why = _footprint_m2(r)
    return (o.scene, o.method, o.protocol, r.seed, "ok", why, r.wwr, r.window_area_m2,
            r.facade_area_m2, footprint_m2, sum(not f.missing for f in r.facades), r.steps,
            result_marks(r, stale=o.status == "stale"))


def _footprint_m2(result: MethodResult) -> tuple[float | None, str]:
    """The area of the result's footprint polygon, or ``None`` and why not."""
    if result.footprint is None:
        return None, ""
    try:
        return float(geojson_to_polygon(result.footprint).area), ""
    except ValueError as exc:
        return None, f"footprint: {exc}"


def _float(cell: Cell) -> float | None:
    return None if cell is None else float(cell)  # type: ignore[arg-type]
