"""What ``report.html`` shows, in memory: a comparison's tables, per-building rows and
provenance, handed over by :func:`metrics.comparison.compare`, or read back once from the
folder it wrote (``python -m metrics.report.html_report --out DIR``).

A table is held as its records: one dict per row, key -> cell (a string, number,
:class:`~metrics.score.aggregate.Summary` or ``None``), made from a
:class:`~metrics.report.tables.Table` (:func:`table_records`) or from its CSV
(:func:`read_table_records`: the ``<key>_mean``/``_std``/``_low``/``_high`` columns become one
``Summary``, numbers become numbers, empty cells ``None``), so both give the same page.
The images, footprints and meshes stay files in the output folder, read where the page
embeds them.
"""

from __future__ import annotations

import json
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from metrics.report.report import (
    PER_BUILDING_NAME,
    TABLE2_NAME,
    TABLE3_NAME,
    read_building_errors_csv,
)
from metrics.report.report_estimates import ESTIMATES_NAME, estimate_rows
from metrics.report.report_paper import PAPER_TABLE2_NAME, PAPER_TABLE3_NAME
from metrics.report.report_seeds import SEED_TABLE_NAME
from metrics.report.report_visible import TABLE2_VISIBLE_NAME
from metrics.report.tables import Cell, Table, read_csv_rows, read_summary
from metrics.score.errors import BuildingErrors
from metrics.score.orientation_errors import ORIENTATION_TABLE_NAME

PROVENANCE_FILE = "provenance.json"
PIPELINE_FOLDER = "2dss_pipeline"  # one facade's pipeline images (the first that writes them)
FOOTPRINTS_FOLDER = "footprints"  # the estimated footprints, <scene>__<method>__<views>.geojson
REPORT_TABLES = (TABLE2_NAME, TABLE3_NAME, PAPER_TABLE2_NAME, PAPER_TABLE3_NAME,
                 TABLE2_VISIBLE_NAME, SEED_TABLE_NAME, ORIENTATION_TABLE_NAME, ESTIMATES_NAME)
"""The tables the page shows (each where the comparison made it)."""
SCORED = (TABLE2_NAME, TABLE3_NAME, PER_BUILDING_NAME)
"""What a comparison that scored something wrote (one on scenes without truth: the estimates)."""
_NUMBER = re.compile(r"-?\d+(\.\d+)?([eE][-+]?\d+)?")

Record = Mapping[str, Cell]


@dataclass(frozen=True)
class ReportData:
    """A comparison as the page needs it.

    ``tables``: the records of each of :data:`REPORT_TABLES` the comparison made, by table
    name; ``rows``: the per-building rows; ``provenance``: the ``provenance.json`` record;
    ``out_dir``: the comparison's output folder (images, footprints, mesh pointers).
    """

    provenance: Mapping[str, Any]
    rows: tuple[BuildingErrors, ...]
    tables: Mapping[str, tuple[Record, ...]]
    out_dir: Path

    def table(self, name: str) -> tuple[Record, ...]:
        """The records of table ``name``; none where the comparison did not make it."""
        return self.tables.get(name, ())


def report_data(tables: Sequence[Table], rows: Sequence[BuildingErrors],
                provenance: Mapping[str, Any], out_dir: Path) -> ReportData:
    """The page's input from a comparison in memory (tables it does not show are left out)."""
    return ReportData(provenance, tuple(rows),
                      {t.name: table_records(t) for t in tables if t.name in REPORT_TABLES},
                      out_dir)


def read_report_data(out_dir: Path) -> ReportData:
    """The page's input read back from a comparison's output folder: the scored rows of
    ``per_building.csv`` and, for the scenes without truth, the estimates table's.

    Raises
    ------
    ValueError
        If ``out_dir`` lacks the provenance, or both the estimates table and one of Table 2,
        Table 3 and ``per_building.csv``.
    """
    scored = all((out_dir / f"{n}.csv").is_file() for n in SCORED)
    wanted = ((f"{n}.csv" for n in SCORED) if scored or not (out_dir / f"{ESTIMATES_NAME}.csv")
              .is_file() else ())
    for name in (*wanted, PROVENANCE_FILE):
        if not (out_dir / name).is_file():
            raise ValueError(f"{out_dir / name} does not exist; run `python -m metrics.compare "
                             f"--out {out_dir}` first")
    tables = {name: read_table_records((out_dir / f"{name}.csv").read_text())
              for name in REPORT_TABLES if (out_dir / f"{name}.csv").is_file()}
    rows = read_building_errors_csv(out_dir / f"{PER_BUILDING_NAME}.csv") if scored else []
    have = {r.scene for r in rows}
    rows += estimate_rows([r for r in tables.get(ESTIMATES_NAME, ()) if r["scene"] not in have])
    return ReportData(json.loads((out_dir / PROVENANCE_FILE).read_text()), tuple(rows), tables,
                      out_dir)


def table_records(table: Table) -> tuple[dict[str, Cell], ...]:
    """One dict per row of ``table``: key -> cell (an empty string as ``None``)."""
    return tuple({k: (None if c == "" else c) for k, c in zip(table.keys, row)}
                 for row in table.rows)


def read_table_records(csv_text: str) -> tuple[dict[str, Cell], ...]:
    """The records of a table's CSV (:func:`metrics.report.tables.to_csv`): its summary
    columns as one :class:`Summary` per key (count 0: not written), numbers as ``int`` or
    ``float``, empty cells as ``None``."""
    rows = read_csv_rows(csv_text)
    if not rows:
        return ()
    columns = list(rows[0])
    summaries = [c[: -len("_mean")] for c in columns
                 if c.endswith("_mean") and c[: -len("_mean")] + "_std" in columns]
    parts = {f"{s}_{p}" for s in summaries for p in ("mean", "std", "low", "high")}
    out = []
    for row in rows:
        record: dict[str, Cell] = {}
        for column in columns:
            if column.endswith("_mean") and column[: -len("_mean")] in summaries:
                key = column[: -len("_mean")]
                record[key] = read_summary(row, key)
            elif column not in parts:
                record[column] = _value(row[column])
        out.append(record)
    return tuple(out)


def _value(text: str) -> Cell:
    if text == "":
        return None
    if not _NUMBER.fullmatch(text):
        return text
    return int(text) if text.lstrip("-").isdigit() else float(text)
