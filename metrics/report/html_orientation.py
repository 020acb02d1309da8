"""The report's "WWR error per orientation" section, from ``table_orientation_wwr.csv``.

A sortable table with a family filter (:mod:`metrics.score.orientation_errors` says what
each column means) and a chart of the mean absolute error per bin for every
method and views, pooled over families. Reads nothing but that CSV; a
comparison made before the table existed gets a one-line note instead.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from envelope.orientation import BIN_NAMES, ORIENTATION_BINS
from metrics.report.html_sections import (
    METHOD_COLOURS,
    Cell,
    chart,
    esc,
    family_filter,
    sortable_table,
)
from metrics.report.tables import format_cell, read_csv_rows
from metrics.score.aggregate import ALL_FAMILIES, family_rank, method_rank, protocol_rank
from metrics.score.orientation_errors import ORIENTATION_TABLE_NAME

TABLE_ID = "orientation"
_SUMMARY_KEYS = (("abs_error_pp", "|WWR error| (pp)"), ("bias_pp", "Bias (pp)"))
_SHARE_KEYS = (("within_5pp_percent", "Within ±5 pp (%)"),
               ("within_10pp_percent", "Within ±10 pp (%)"))


def orientation_section(out_dir: Path) -> str:
    """``<h2>`` + table + chart of the per-orientation WWR errors in ``out_dir``."""
    path = out_dir / f"{ORIENTATION_TABLE_NAME}.csv"
    heading = "<h2>WWR error per orientation</h2>"
    if not path.is_file():
        return (f'{heading}<p class="muted">{esc(path.name)} is missing: rerun `python -m '
                "metrics.compare` to add the per-orientation errors</p>")
    rows = read_csv_rows(path.read_text())
    if not rows:
        return f'{heading}<p class="muted">no facade could be compared per orientation</p>'
    return (f"{heading}<p>Error of each method's WWR per facade orientation (EnergyPlus "
            "bins, from the truth facades' azimuths), in percentage points, and the share "
            "of facades within ±5 and ±10 points.</p>"
            + orientation_table_html(rows) + orientation_chart(rows))


def orientation_table_html(rows: Sequence[dict[str, str]]) -> str:
    """The table from its CSV rows, filterable by family."""
    columns = ["Family", "Method", "Views", "Orientation", "Buildings", "Facades",
               *(label for _, label in _SUMMARY_KEYS), *(label for _, label in _SHARE_KEYS)]
    cells: list[list[Cell]] = []
    for r in rows:
        row: list[Cell] = [(r[k], r[k]) for k in ("family", "method", "protocol",
                                                   "orientation", "buildings", "facades")]
        row[3] = (r["orientation"], str(ORIENTATION_BINS.index(r["orientation"])))
        for key, _ in _SUMMARY_KEYS:
            mean, std = r.get(f"{key}_mean", ""), r.get(f"{key}_std", "")
            text = "–" if not mean else f"{float(mean):.2f} ± {float(std):.2f}"
            row.append((text, mean))
        for key, _ in _SHARE_KEYS:
            value = r.get(key, "")
            row.append((format_cell(float(value) if value else None, 1), value))
        cells.append(row)
    attrs = [{"family": r["family"], "method": r["method"], "protocol": r["protocol"]}
             for r in rows]
    families = sorted({r["family"] for r in rows}, key=family_rank)
    return (family_filter(TABLE_ID, families) + sortable_table(TABLE_ID, columns, cells, attrs))


def orientation_chart(rows: Sequence[dict[str, str]]) -> str:
    """Mean |WWR error| per bin (x) with ± std, one bar per method and views, all families."""
    import plotly.graph_objects as go

    pooled = [r for r in rows if r["family"] == ALL_FAMILIES]
    series = sorted({(r["method"], r["protocol"]) for r in pooled},
                    key=lambda s: (method_rank(s[0]), protocol_rank(s[1])))
    fig = go.Figure()
    for k, (method, protocol) in enumerate(series):
        mine = {r["orientation"]: r for r in pooled
                if (r["method"], r["protocol"]) == (method, protocol)}
        means = [_float(mine.get(b, {}).get("abs_error_pp_mean")) for b in ORIENTATION_BINS]
        stds = [_float(mine.get(b, {}).get("abs_error_pp_std")) for b in ORIENTATION_BINS]
        fig.add_trace(go.Bar(x=[BIN_NAMES[b] for b in ORIENTATION_BINS], y=means,
                             error_y={"type": "data", "array": stds},
                             name=f"{method} ({protocol})",
                             marker_color=METHOD_COLOURS[k % len(METHOD_COLOURS)]))
    fig.update_layout(barmode="group", yaxis={"title": "|WWR error| (percentage points)"},
                      margin={"t": 30, "b": 40})
    return chart("chart-orientation", fig.to_json(), height_px=320)


def _float(text: str | None) -> float | None:
    return float(text) if text else None
