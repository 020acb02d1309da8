"""The report's estimates section, from the estimates table (metrics.report.report_estimates).

Made where a scene has no ground truth: it says so first (the table's note: no errors at all,
or errors over the scenes with truth only), then each method's figures per building in a
sortable table, a failed run's reason beside it.
"""

from __future__ import annotations

from collections.abc import Sequence

from markupsafe import Markup

from metrics.report.html_sections import Cell, label_cell, number_cell
from metrics.report.report_data import Record
from metrics.report.templating import render

COLUMNS = ("Scene", "Method", "Views", "Seed", "Status", "WWR", "Window (m²)", "Facade (m²)",
           "Footprint (m²)", "Facades", "Why / marks")
_NUMBERS = (("wwr", ".4f"), ("window_m2", ".2f"), ("facade_m2", ".2f"), ("footprint_m2", ".2f"))


def estimates_section(records: Sequence[Record], truth_note: str) -> Markup:
    """``<h2>`` + what has no truth (``truth_note``) + the estimates table; empty without
    records (every scene had truth)."""
    if not records:
        return Markup("")
    rows: list[list[Cell]] = []
    for r in records:
        row = [label_cell(r[k]) for k in ("scene", "method", "protocol", "seed", "status")]
        row += [number_cell(_number(r[k]), fmt) for k, fmt in _NUMBERS]
        note = "; ".join(str(r[k]) for k in ("reason", "marks") if r[k])
        rows.append([*row, label_cell(r["facades"]), (note, note)])
    return render("estimates.html.j2", truth_note=truth_note, columns=COLUMNS, rows=rows,
                  attrs=[{"status": str(r["status"])} for r in records])


def _number(cell: object) -> float | None:
    return None if cell is None else float(cell)  # type: ignore[arg-type]
