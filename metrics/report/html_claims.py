"""HTML sections of the report for the claims' qualifiers: errors against the visible facade
truth and the seed-to-seed spread, each read from the CSV :mod:`metrics.compare` wrote."""

from __future__ import annotations

from pathlib import Path

from metrics.report.html_sections import Cell, esc, sortable_table
from metrics.report.report_seeds import SEED_TABLE_NAME
from metrics.report.report_visible import TABLE2_VISIBLE_NAME, VISIBLE_NOTE
from metrics.report.tables import format_cell, read_csv_rows, read_summary

LABEL_KEYS = ("family", "method", "protocol", "buildings", "seeds")


def claims_sections(out_dir: Path) -> str:
    """The visible-truth Table 2 and the seed spread, each where its CSV exists."""
    parts = []
    for name, heading, decimals, note in (
        (TABLE2_VISIBLE_NAME, "Table 2 against the full and the visible facade", 2,
         VISIBLE_NOTE),
        (SEED_TABLE_NAME, "Seed-to-seed spread of repeated trainings", 3,
         "std over one building's seeds (ddof=1), mean ± std over buildings"),
    ):
        path = out_dir / f"{name}.csv"
        if path.is_file():
            parts.append(f"<h2>{esc(heading)}</h2>"
                         f"{csv_table_html(name, read_csv_rows(path.read_text()), decimals)}"
                         f'<p class="ref">{esc(note)}</p>')
    return "".join(parts)


def csv_table_html(table_id: str, rows: list[dict[str, str]], decimals: int) -> str:
    """A sortable table of a CSV written by :func:`metrics.report.tables.to_csv`: label columns as
    they are, each summary column (``<key>_mean`` ...) as ``mean ± std [low, high]``."""
    if not rows:
        return '<p class="muted">no rows</p>'
    keys = list(rows[0])
    labels = [k for k in keys if k in LABEL_KEYS]
    summaries = [k[: -len("_mean")] for k in keys if k.endswith("_mean")]
    cells: list[list[Cell]] = []
    for r in rows:
        row: list[Cell] = [(r[k] or "–", r[k]) for k in labels]
        for key in summaries:
            s = read_summary(r, key)
            row.append((format_cell(s, decimals), "" if s.mean is None else repr(s.mean)))
        cells.append(row)
    return sortable_table(table_id, labels + summaries, cells)
