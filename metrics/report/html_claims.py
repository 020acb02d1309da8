"""The report's sections for the claims' qualifiers: errors against the visible facade
truth and the seed-to-seed spread, each where the comparison made its table."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from markupsafe import Markup

from metrics.report.html_sections import Cell, label_cell, summary_cell
from metrics.report.report_data import Record
from metrics.report.report_seeds import SEED_TABLE_NAME
from metrics.report.report_visible import TABLE2_VISIBLE_NAME, VISIBLE_NOTE
from metrics.report.templating import render
from metrics.score.aggregate import Summary

LABEL_KEYS = ("family", "method", "protocol", "buildings", "seeds")
SECTIONS = (
    (TABLE2_VISIBLE_NAME, "Table 2 against the full and the visible facade", 2, VISIBLE_NOTE),
    (SEED_TABLE_NAME, "Seed-to-seed spread of repeated trainings", 3,
     "std over one building's seeds (ddof=1), mean ± std over buildings"),
)


def claims_sections(tables: Mapping[str, Sequence[Record]]) -> Markup:
    """The visible-truth Table 2 and the seed spread, each where ``tables`` (records by table
    name) holds it."""
    sections = []
    for name, heading, decimals, note in SECTIONS:
        if name in tables:
            columns, rows = records_table(tables[name], decimals)
            sections.append({"heading": heading, "table_id": name, "columns": columns,
                             "rows": rows, "note": note})
    return render("claims.html.j2", sections=sections)


def records_table(records: Sequence[Record],
                  decimals: int) -> tuple[list[str], list[list[Cell]]]:
    """Columns and cells of a sortable table of ``records``: the label columns as they are,
    each summary column as ``mean ± std [low, high]``."""
    if not records:
        return [], []
    keys = list(records[0])
    labels = [k for k in keys if k in LABEL_KEYS]
    summaries = [k for k in keys if any(isinstance(r.get(k), Summary) for r in records)]
    cells = [[label_cell(r[k]) for k in labels] + [summary_cell(r[k], decimals)
                                                   for k in summaries] for r in records]
    return labels + summaries, cells
