"""The comparison's tables: Table 2 (errors), Table 3 (footprint IoU), per-building and per-facade.

The per-building CSV is also the file the figures read back
(:func:`read_building_errors_csv`), so it keeps every figure at full precision.
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import fields
from pathlib import Path
from typing import Any

from metrics.report.tables import Table, read_csv_rows
from metrics.score.aggregate import ALL_FAMILIES, GroupSummary
from metrics.score.bootstrap import INTERVAL_TEXT
from metrics.score.errors import CUT_SHORT, STALE, BuildingErrors, FacadeErrors, RunTiming

TABLE2_NAME = "table2_errors"
TABLE3_NAME = "table3_footprint_iou"
PER_BUILDING_NAME = "per_building"
PER_FACADE_NAME = "per_facade"
TIMING_NAME = "timing"


def table2_errors(groups: Sequence[GroupSummary]) -> Table:
    """Table 2: WWR, window-area and facade-area APE (%) per family, method and views."""
    rows = tuple(
        (g.family, g.method, g.protocol, g.buildings, g.failed,
         g.wwr_ape, g.window_ape, g.facade_ape, g.steps, g.marks)
        for g in groups
    )
    return Table(
        name=TABLE2_NAME,
        title="Absolute percentage error (%) of WWR, window area and facade area, mean ± std "
              f"[{INTERVAL_TEXT}]",
        columns=("Family", "Method", "Views", "Buildings", "Failed",
                 "WWR error (%)", "Window error (%)", "Facade error (%)", "Steps", "Marks"),
        keys=("family", "method", "protocol", "buildings", "failed",
              "wwr_ape", "window_ape", "facade_ape", "steps", "marks"),
        rows=rows,
        notes=_failure_notes(groups) + _mark_notes(groups),
    )


def table3_footprint_iou(
    groups: Sequence[GroupSummary], footprint_methods: Collection[str]
) -> Table:
    """Table 3: footprint IoU per family for the methods that estimate a footprint.

    A method is listed when it is in ``footprint_methods`` or any of its
    groups has an IoU, so a footprint method that failed everywhere still shows.
    """
    methods = set(footprint_methods) | {g.method for g in groups if g.footprint_iou.count}
    kept = [g for g in groups if g.method in methods]
    return Table(
        name=TABLE3_NAME,
        title=f"Footprint IoU with the ground truth, mean ± std [{INTERVAL_TEXT}]",
        columns=("Family", "Method", "Views", "Buildings", "Failed", "Footprint IoU", "Steps",
                 "Marks"),
        keys=("family", "method", "protocol", "buildings", "failed", "footprint_iou", "steps",
              "marks"),
        rows=tuple(
            (g.family, g.method, g.protocol, g.buildings, g.failed, g.footprint_iou, g.steps,
             g.marks)
            for g in kept
        ),
        notes=(_failure_notes(kept) + _mark_notes(kept))
        or (() if kept else ("no method estimates a footprint",)),
        decimals=3,
    )


def per_building_table(rows: Sequence[BuildingErrors]) -> Table:
    """Every (scene, method, protocol): status, reason, estimates, truth and errors."""
    names = tuple(f.name for f in fields(BuildingErrors))
    return Table(
        name=PER_BUILDING_NAME,
        title="Estimates, truth and errors per building (APE in %, areas in m²)",
        columns=names,
        keys=names,
        rows=tuple(tuple(getattr(r, n) for n in names) for r in rows),
        decimals=4,
    )


def per_facade_table(rows: Sequence[FacadeErrors]) -> Table:
    """Every facade of every run, paired by the one scoring rule (matched, missed, false
    positive): status, reason, WWR and errors (APE in %)."""
    names = tuple(f.name for f in fields(FacadeErrors))
    return Table(
        name=PER_FACADE_NAME,
        title="Errors per facade (APE in %)",
        columns=names,
        keys=names,
        rows=tuple(tuple(getattr(r, n) for n in names) for r in rows),
        decimals=4,
    )


def read_building_errors_csv(path: str | Path) -> list[BuildingErrors]:
    """Read back the per-building CSV written from :func:`per_building_table`.

    Raises
    ------
    ValueError
        If the file is missing or lacks a column of :class:`BuildingErrors`.
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path} does not exist; run `python -m metrics.compare` first")
    rows = read_csv_rows(path.read_text())
    out = []
    for i, row in enumerate(rows):
        try:
            out.append(BuildingErrors(**{
                f.name: _parse(row[f.name], f.type) for f in fields(BuildingErrors)
            }))
        except (KeyError, ValueError) as exc:
            raise ValueError(f"{path}, data row {i + 1}: not a per-building row ({exc})") from exc
    return out


def _parse(text: str, type_name: Any) -> Any:
    if "float" in str(type_name):
        return float(text) if text != "" else None
    if "int" in str(type_name):
        return int(text) if text != "" else None
    return text


def timing_table(timings: Sequence[RunTiming]) -> Table:
    """How long each run took (s) and whether it ran now or was reused: the one output that
    differs between reruns, so it is kept out of the other tables."""
    names = tuple(f.name for f in fields(RunTiming))
    return Table(
        name=TIMING_NAME,
        title="Wall time per run (s; reused results keep the time of the run that made them)",
        columns=names,
        keys=names,
        rows=tuple(tuple(getattr(t, n) for n in names) for t in timings),
        decimals=1,
    )


def _mark_notes(groups: Sequence[GroupSummary]) -> tuple[str, ...]:
    notes = []
    if any(CUT_SHORT in g.marks for g in groups):
        notes.append(f"{CUT_SHORT}: the wall-clock safety cap stopped training before its step "
                     "budget; the figure is not the budget's")
    if any(STALE in g.marks for g in groups):
        notes.append(f"{STALE}: kept with --reuse-stale although made by other code or "
                     "settings; `python -m metrics.compare --explain SCENE METHOD` says what")
    return tuple(notes)


def _failure_notes(groups: Sequence[GroupSummary]) -> tuple[str, ...]:
    return tuple(
        f"failed: {g.family} / {g.method} / {g.protocol}: {reason}"
        for g in groups if g.family != ALL_FAMILIES
        for reason in g.reasons
    )
