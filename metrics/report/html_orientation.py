"""The report's "WWR error per orientation" section, from the per-orientation table.

A sortable table with a family filter (:mod:`metrics.score.orientation_errors` says what
each column means) and a chart of the mean absolute error per bin for every
method and views, pooled over families. A comparison made before the table existed gets a
one-line note instead.
"""

from __future__ import annotations

from collections.abc import Sequence

from markupsafe import Markup

from envelope.orientation import BIN_NAMES, ORIENTATION_BINS
from metrics.report.html_sections import Cell, colour, label_cell, summary_cell
from metrics.report.report_data import Record
from metrics.report.tables import format_cell
from metrics.report.templating import render
from metrics.score.aggregate import ALL_FAMILIES, Summary, family_rank, method_rank, protocol_rank
from metrics.score.orientation_errors import ORIENTATION_TABLE_NAME

TABLE_ID = "orientation"
_SUMMARY_KEYS = (("abs_error_pp", "|WWR error| (pp)"), ("bias_pp", "Bias (pp)"))
_SHARE_KEYS = (("within_5pp_percent", "Within ±5 pp (%)"),
               ("within_10pp_percent", "Within ±10 pp (%)"))


def orientation_section(records: Sequence[Record] | None) -> Markup:
    """``<h2>`` + table + chart of the per-orientation WWR errors (``records``: the table's;
    ``None``: the comparison did not make it)."""
    if not records:
        return render("orientation.html.j2", missing=(
            f"{ORIENTATION_TABLE_NAME}.csv" if records is None else None), rows=[])
    columns = ["Family", "Method", "Views", "Orientation", "Buildings", "Facades",
               *(label for _, label in _SUMMARY_KEYS), *(label for _, label in _SHARE_KEYS)]
    rows: list[list[Cell]] = []
    for r in records:
        row = [label_cell(r[k]) for k in ("family", "method", "protocol")]
        row.append((str(r["orientation"]), str(ORIENTATION_BINS.index(r["orientation"]))))
        row += [label_cell(r[k]) for k in ("buildings", "facades")]
        row += [_mean_std(r[key]) for key, _ in _SUMMARY_KEYS]
        row += [_share(r[key]) for key, _ in _SHARE_KEYS]
        rows.append(row)
    return render("orientation.html.j2", missing=None, table_id=TABLE_ID, columns=columns,
                  rows=rows, attrs=[_attrs(r) for r in records],
                  families=sorted({str(r["family"]) for r in records}, key=family_rank),
                  figure_json=orientation_figure_json(records))


def _mean_std(value) -> Cell:
    """``mean ± std`` (no interval: the buildings of one bin are few)."""
    if not isinstance(value, Summary) or value.mean is None:
        return summary_cell(None, 2)
    std = value.std if value.std is not None else 0.0
    return f"{value.mean:.2f} ± {std:.2f}", repr(value.mean)


def _share(value) -> Cell:
    return format_cell(value, 1), "" if value is None else repr(value)


def _attrs(r: Record) -> dict[str, str]:
    return {k: str(r[k]) for k in ("family", "method", "protocol")}


def orientation_figure_json(records: Sequence[Record]) -> str:
    """Mean |WWR error| per bin (x) with ± std, one bar per method and views, all families."""
    import plotly.graph_objects as go

    pooled = [r for r in records if r["family"] == ALL_FAMILIES]
    series = sorted({(r["method"], r["protocol"]) for r in pooled},
                    key=lambda s: (method_rank(s[0]), protocol_rank(s[1])))
    fig = go.Figure()
    for k, (method, protocol) in enumerate(series):
        mine = {r["orientation"]: r["abs_error_pp"] for r in pooled
                if (r["method"], r["protocol"]) == (method, protocol)}
        stats = [mine.get(b) for b in ORIENTATION_BINS]
        fig.add_trace(go.Bar(x=[BIN_NAMES[b] for b in ORIENTATION_BINS],
                             y=[s.mean if isinstance(s, Summary) else None for s in stats],
                             error_y={"type": "data", "array": [
                                 s.std if isinstance(s, Summary) else None for s in stats]},
                             name=f"{method} ({protocol})", marker_color=colour(k)))
    fig.update_layout(barmode="group", yaxis={"title": "|WWR error| (percentage points)"},
                      margin={"t": 30, "b": 40})
    return fig.to_json()
