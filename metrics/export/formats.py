"""The export's files, each made from the one table (:mod:`metrics.export.table`).

Every function is pure: rows in, text or a JSON-ready dict out. CSV files
start with ``#`` comment lines (the conventions of :mod:`envelope.orientation`,
what made the file, each building's north); JSON files carry the same in
``metadata``. A facade with WWR 0 is 0 everywhere; an orientation no facade
faces is empty in CSV and ``null`` (or left out, where a tool's own dict lists
only the orientations it has) in JSON.

Formats (``docs/export.md`` has the details and a worked example):

- ``facades.csv``, ``orientations.csv``: the table itself;
- ``energyplus_wwr.csv``: EnergyPlus's "Window-Wall Ratio" report layout;
- ``cea_architecture.csv``: City Energy Analyst ``wwr_north`` ... columns (fractions);
- ``geomeppy.json``: ``wwr_map`` and per-orientation ``set_wwr`` values, and the
  truth's footprint as ``add_block`` takes it;
- ``honeybee.json``: ratios [N, E, S, W] (Apertures by Ratio: north, then clockwise);
- ``teaser.json``: ``window_area`` and ``outer_area`` dicts keyed by 0, 90, 180, 270.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Mapping, Sequence
from dataclasses import fields
from typing import Any

from envelope.orientation import BIN_CENTRE_DEG, BIN_NAMES, CONVENTIONS, ORIENTATION_BINS
from envelope.wwr import wwr_from_areas
from metrics.export.table import FacadeRow, North, OrientationRow

DECIMALS = 6  # m² and WWR fractions are written rounded to 1e-6
HONEYBEE_MAX_RATIO = 0.95  # Apertures by Ratio accepts ratios in [0, 0.95]
ENERGYPLUS_COLUMNS = ("Total", "North (315 to 45 deg)", "East (45 to 135 deg)",
                      "South (135 to 225 deg)", "West (225 to 315 deg)")
GEOMEPPY_NOTES = (
    "geomeppy 0.12.2 set_wwr(wwr_map=...) looks each wall up by its exact azimuth "
    "(a rotated wall at 29.9999 misses key 30.0) and replaces a 0 entry by its `wwr` "
    "argument (`wwr_map.get(azimuth) or wwr`); with wwr=0 it stops at the first wall "
    "whose WWR is 0 and leaves the remaining walls without windows",
    "use set_wwr_by_orientation instead: call set_wwr(wwr=w, orientation=o) for each "
    "orientation o with w > 0 (geomeppy takes walls within 45 degrees of it; a wall at "
    "exactly 45, 135, 225 or 315 degrees is in no orientation there) on a model "
    "without windows, and skip w = 0",
    "geomeppy reads azimuths from the IDF geometry and ignores Building North Axis: "
    "build the block from `block` (true-north coordinates) with North Axis 0",
)

Key = tuple[str, str, str]  # (building, method, protocol)


def header_lines(produced_by: str, norths: Mapping[str, North]) -> tuple[str, ...]:
    """The lines every export starts with: what made it, the conventions, each north."""
    return (produced_by, *CONVENTIONS, *(
        f"north of {b}: {n.deg:g} deg ({n.source})" for b, n in sorted(norths.items())))


def metadata(produced_by: str, norths: Mapping[str, North]) -> dict[str, Any]:
    """The ``metadata`` object of a JSON export (the same content as :func:`header_lines`)."""
    return {"produced_by": produced_by, "conventions": list(CONVENTIONS),
            "north": {b: {"north_deg": n.deg, "north_source": n.source}
                      for b, n in sorted(norths.items())}}


def facades_csv(rows: Sequence[FacadeRow], header: Sequence[str]) -> str:
    """Every facade of every building and method (the table itself)."""
    names = [f.name for f in fields(FacadeRow)]
    return _csv(header, names, [[_cell(getattr(r, n)) for n in names] for r in rows])


def orientations_csv(rows: Sequence[OrientationRow], header: Sequence[str]) -> str:
    """The per-orientation sums: one row per building, method, protocol and bin."""
    names = [f.name for f in fields(OrientationRow)]
    return _csv(header, names, [[_cell(getattr(r, n)) for n in names] for r in rows])


def energyplus_csv(rows: Sequence[OrientationRow], header: Sequence[str]) -> str:
    """EnergyPlus's "Window-Wall Ratio" table per building and method: gross wall area,
    window opening area (m²) and gross window-wall ratio (%), total and per bin."""
    out = []
    for (building, method, protocol), by_bin in _by_estimate(rows).items():
        known = [r for r in by_bin.values() if r.gross_m2 is not None]
        total_gross = sum(r.gross_m2 for r in known) if known else None
        total_window = sum(r.window_m2 for r in known) if known else None
        total_wwr = (None if total_gross is None
                     else wwr_from_areas(total_window, max(total_gross - total_window, 0.0), 0))
        columns = [(total_gross, total_window, total_wwr)] + [
            (by_bin[b].gross_m2, by_bin[b].window_m2, by_bin[b].wwr) for b in ORIENTATION_BINS]
        for i, label in enumerate(("Gross Wall Area [m2]", "Window Opening Area [m2]",
                                   "Gross Window-Wall Ratio [%]")):
            values = [c[i] if i < 2 or c[i] is None else 100.0 * c[i] for c in columns]
            out.append([building, method, protocol, label, *(_cell(v) for v in values)])
    return _csv(header, ["building", "method", "protocol", "row", *ENERGYPLUS_COLUMNS], out)


def cea_csv(rows: Sequence[OrientationRow], header: Sequence[str]) -> str:
    """City Energy Analyst architecture columns ``wwr_north`` ... (fractions 0-1) per building
    (``name``) and method; empty where no facade faces that way."""
    out = [[building, method, protocol, *(_cell(by_bin[b].wwr) for b in ORIENTATION_BINS)]
           for (building, method, protocol), by_bin in _by_estimate(rows).items()]
    return _csv(header, ["name", "method", "protocol",
                         *(f"wwr_{BIN_NAMES[b]}" for b in ORIENTATION_BINS)], out)


def geomeppy_json(rows: Sequence[OrientationRow], blocks: Mapping[str, dict],
                  meta: dict[str, Any]) -> dict[str, Any]:
    """Per building: ``block`` (footprint and height for ``IDF.add_block``, when the truth
    gives them) and per method ``wwr_map`` {bin azimuth: WWR} and ``set_wwr_by_orientation``
    {"north": WWR, ...}; orientations no facade faces are left out."""
    buildings: dict[str, Any] = {}
    for (building, method, protocol), by_bin in _by_estimate(rows).items():
        entry = buildings.setdefault(building, {"block": blocks.get(building), "estimates": []})
        present = [b for b in ORIENTATION_BINS if by_bin[b].wwr is not None]
        entry["estimates"].append({
            "method": method, "protocol": protocol,
            "wwr_map": {f"{BIN_CENTRE_DEG[b]:g}": _num(by_bin[b].wwr) for b in present},
            "set_wwr_by_orientation": {BIN_NAMES[b]: _num(by_bin[b].wwr) for b in present},
        })
    return {"metadata": {**meta, "geomeppy_notes": list(GEOMEPPY_NOTES)},
            "buildings": buildings}


def honeybee_json(rows: Sequence[OrientationRow], meta: dict[str, Any]) -> dict[str, Any]:
    """Per building and method the ratios [N, E, S, W] for Honeybee's Apertures by Ratio
    (north first, then clockwise); ``null`` where no facade faces that way."""
    buildings: dict[str, list] = {}
    for (building, method, protocol), by_bin in _by_estimate(rows).items():
        ratios = [_num(by_bin[b].wwr) for b in ORIENTATION_BINS]
        over = [BIN_NAMES[b] for b in ORIENTATION_BINS
                if by_bin[b].wwr is not None and by_bin[b].wwr > HONEYBEE_MAX_RATIO]
        buildings.setdefault(building, []).append({
            "method": method, "protocol": protocol, "ratios": ratios,
            **({"note": f"ratio above Honeybee's {HONEYBEE_MAX_RATIO} limit: "
                        + ", ".join(over)} if over else {})})
    note = ("ratios: [north, east, south, west], fractions; null: no facade faces this way, "
            "choose a value for walls of your model that do")
    return {"metadata": {**meta, "honeybee_notes": [note]}, "buildings": buildings}


def teaser_json(rows: Sequence[OrientationRow], meta: dict[str, Any]) -> dict[str, Any]:
    """Per building and method TEASER's ``window_area`` and ``outer_area`` (opaque wall,
    m²) keyed by orientation 0, 90, 180, 270 (as strings: ``float(key)`` in TEASER), with
    ``door_area`` where doors are known; orientations no facade faces are left out."""
    buildings: dict[str, list] = {}
    for (building, method, protocol), by_bin in _by_estimate(rows).items():
        present = [b for b in ORIENTATION_BINS if by_bin[b].wwr is not None]
        key = {b: f"{BIN_CENTRE_DEG[b]:.1f}" for b in present}
        doors_known = all(by_bin[b].door_m2 is not None for b in present)
        entry: dict[str, Any] = {
            "method": method, "protocol": protocol,
            "window_area": {key[b]: _num(by_bin[b].window_m2) for b in present},
            "outer_area": {key[b]: _num(_opaque_m2(by_bin[b], doors_known)) for b in present},
        }
        if doors_known:
            entry["door_area"] = {key[b]: _num(by_bin[b].door_m2) for b in present}
        buildings.setdefault(building, []).append(entry)
    note = ("outer_area: opaque wall without windows; without doors where door_area is "
            "given, else doors included (the method does not separate them)")
    return {"metadata": {**meta, "teaser_notes": [note]}, "buildings": buildings}


def _opaque_m2(row: OrientationRow, doors_known: bool) -> float | None:
    if doors_known and row.wall_m2 is not None:
        return row.wall_m2
    return max(row.gross_m2 - row.window_m2, 0.0)


def _by_estimate(rows: Sequence[OrientationRow]) -> dict[Key, dict[str, OrientationRow]]:
    out: dict[Key, dict[str, OrientationRow]] = {}
    for r in rows:
        out.setdefault((r.building, r.method, r.protocol), {})[r.orientation] = r
    return out


def _csv(header: Sequence[str], names: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    buf = io.StringIO()
    buf.write("".join(f"# {line}\n" for line in header))
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(names)
    writer.writerows(rows)
    return buf.getvalue()


def _num(value: float | None) -> float | None:
    return None if value is None else round(float(value), DECIMALS) + 0.0


def _cell(value: object) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return repr(_num(value))
    return str(value)
