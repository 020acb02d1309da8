"""``report.html``: a comparison as one self-contained page, from the comparison in memory
(:func:`write_report`, called by :func:`metrics.comparison.compare`) or, with
``python -m metrics.report.html_report --out DIR``, rebuilt from the folder it wrote (read
once into the same :class:`~metrics.report.report_data.ReportData`).

The page is rendered from jinja2 templates (``templates/``, autoescaped): Tables 2 and 3 with
the paper's figures beside ours, the claims' qualifiers, charts, the per-orientation errors,
one section per building and the provenance. Where a scene has no ground truth the page says
so first and shows the estimates table (:mod:`metrics.report.html_estimates`); where none
has, there are no error tables or charts at all. plotly.js and every image are embedded, so the
file opens offline and can be sent on its own.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from markupsafe import Markup

from envelope.atomic import write_text_atomic
from metrics.report.html_building import building_section
from metrics.report.html_claims import claims_sections
from metrics.report.html_estimates import estimates_section
from metrics.report.html_orientation import orientation_section
from metrics.report.html_sections import Cell, chart, colour, label_cell, summary_cell
from metrics.report.paper_tables import (
    CAVEATS,
    PAPER_KEYS,
    PAPER_TABLE2_LABEL,
    PAPER_TABLE3_LABEL,
)
from metrics.report.report import TABLE2_NAME, TABLE3_NAME
from metrics.report.report_data import Record, ReportData, read_report_data
from metrics.report.report_estimates import ESTIMATES_NAME, truth_note
from metrics.report.report_paper import PAPER_TABLE2_NAME, PAPER_TABLE3_NAME
from metrics.report.templating import render
from metrics.score.aggregate import Summary, family_rank, method_rank, protocol_rank
from metrics.score.bootstrap import INTERVAL_TEXT
from metrics.score.errors import NO_TRUTH_FAMILY, BuildingErrors
from metrics.score.orientation_errors import ORIENTATION_TABLE_NAME

REPORT_FILE = "report.html"
ERROR_COLUMNS = (("wwr_ape", "WWR error (%)"), ("window_ape", "Window error (%)"),
                 ("facade_ape", "Facade error (%)"))
# our Table 2 error key -> the column of the paper's figure in the paper comparison table
_PAPER_COLUMN = {"wwr_ape": "paper_wwr_ape", "window_ape": "paper_window_ape",
                 "facade_ape": "paper_wall_ape"}
_LABELS = ("family", "method", "protocol", "buildings", "failed")


def write_report(data: ReportData) -> Path:
    """Write ``report.html`` into ``data.out_dir`` (atomically); returns its path."""
    path = data.out_dir / REPORT_FILE
    write_text_atomic(path, build_report(data))
    return path


def build_report(data: ReportData) -> str:
    """The report's HTML text."""
    from plotly.offline import get_plotlyjs

    table2 = data.table(TABLE2_NAME)
    scenes = sorted({(r.family, r.scene) for r in data.rows},
                    key=lambda s: (family_rank(s[0]), s[1]))
    source = Path(data.provenance.get("data", ""))
    without_truth = sorted({s for f, s in scenes if f == NO_TRUTH_FAMILY})
    return render(
        "report.html.j2", plotly_js=get_plotlyjs(),
        produced_by=data.provenance.get("produced_by", ""),
        scored=TABLE2_NAME in data.tables,
        estimates=estimates_section(data.table(ESTIMATES_NAME),
                                    truth_note(without_truth, len(scenes))),
        table2=table2_html(table2, data.table(PAPER_TABLE2_NAME)),
        table3=table3_html(data.table(TABLE3_NAME), data.table(PAPER_TABLE3_NAME)),
        claims=claims_sections(data.tables), errors_chart=errors_chart(table2),
        iou_chart=iou_chart(data.rows),
        orientation=orientation_section(data.tables.get(ORIENTATION_TABLE_NAME)),
        scenes=scenes,
        buildings=[building_section(s, [r for r in data.rows if r.scene == s], source,
                                    data.out_dir) for _, s in scenes],
        **provenance_footer(data.provenance),
    ) + "\n"


def _by_row(records: Sequence[Record]) -> dict[tuple[Any, Any, Any], Record]:
    return {(r["family"], r["method"], r["protocol"]): r for r in records}


def _attrs(records: Sequence[Record]) -> list[dict[str, str]]:
    return [{k: str(r[k]) for k in ("family", "method", "protocol")} for r in records]


def _budget_cells(r: Record) -> list[Cell]:
    """Steps (``–`` for none) and marks (empty for none)."""
    marks = "" if r["marks"] is None else str(r["marks"])
    return [label_cell(r["steps"]), (marks, marks)]


def table2_html(records: Sequence[Record], paper_records: Sequence[Record] = ()) -> Markup:
    """Table 2 from its records, the paper's published errors beside ours (``paper_records``:
    those of the paper comparison table, :mod:`metrics.report.report_paper`)."""
    paper = _by_row(paper_records)
    columns = ["Family", "Method", "Views", "Buildings", "Failed"]
    for key, label in ERROR_COLUMNS:
        paper_label = "Wall" if key == "facade_ape" else label.split(" (")[0]
        columns += [label, f"{paper_label}, {PAPER_TABLE2_LABEL}"]
    columns += ["Steps", "Marks"]
    rows = []
    for r in records:
        ref = paper.get((r["family"], r["method"], r["protocol"]))
        row = [label_cell(r[k]) for k in _LABELS]
        for key, _ in ERROR_COLUMNS:
            row += [summary_cell(r[key], 2),
                    summary_cell(ref[_PAPER_COLUMN[key]] if ref else None, 2)]
        rows.append(row + _budget_cells(r))
    return render("table2.html.j2", columns=columns, rows=rows, attrs=_attrs(records),
                  families=sorted({str(r["family"]) for r in records}, key=family_rank),
                  paper_label=PAPER_TABLE2_LABEL, paper_keys=", ".join(PAPER_KEYS),
                  interval_text=INTERVAL_TEXT, caveats=CAVEATS)


def table3_html(records: Sequence[Record], paper_records: Sequence[Record] = ()) -> Markup:
    """Table 3 from its records, BuildNet3D's published IoU beside ours (``paper_records``:
    those of the paper comparison table, :mod:`metrics.report.report_paper`)."""
    paper = _by_row(paper_records)
    columns = ["Family", "Method", "Views", "Buildings", "Failed", "Footprint IoU",
               f"IoU, {PAPER_TABLE3_LABEL}", "Steps", "Marks"]
    rows = []
    for r in records:
        ref = paper.get((r["family"], r["method"], r["protocol"]))
        rows.append([label_cell(r[k]) for k in _LABELS]
                    + [summary_cell(r["footprint_iou"], 3),
                       summary_cell(ref["paper_footprint_iou"] if ref else None, 3)]
                    + _budget_cells(r))
    return render("table3.html.j2", columns=columns, rows=rows, attrs=_attrs(records),
                  paper_label=PAPER_TABLE3_LABEL)


def errors_chart(records: Sequence[Record]) -> Markup:
    """Table 2 as grouped bars (family on x, a bar per method and views, ± std), per error."""
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    fig = make_subplots(rows=1, cols=len(ERROR_COLUMNS),
                        subplot_titles=[label for _, label in ERROR_COLUMNS])
    series = sorted({(r["method"], r["protocol"]) for r in records},
                    key=lambda s: (method_rank(s[0]), protocol_rank(s[1])))
    for k, (method, protocol) in enumerate(series):
        mine = sorted((r for r in records if (r["method"], r["protocol"]) == (method, protocol)),
                      key=lambda r: family_rank(r["family"]))
        for col, (key, _) in enumerate(ERROR_COLUMNS, start=1):
            stats = [r[key] if isinstance(r[key], Summary) else Summary(None, None, 0)
                     for r in mine]
            fig.add_trace(go.Bar(
                x=[r["family"] for r in mine], y=[s.mean for s in stats],
                error_y={"type": "data", "array": [s.std for s in stats]},
                name=f"{method} ({protocol})", legendgroup=f"{method}{protocol}",
                showlegend=col == 1, marker_color=colour(k)), row=1, col=col)
    fig.update_layout(barmode="group", margin={"t": 40, "b": 40})
    return chart("chart-errors", fig.to_json())


def iou_chart(rows: Sequence[BuildingErrors]) -> Markup:
    """Footprint IoU per building, one bar per method and views."""
    import plotly.graph_objects as go

    rows = [r for r in rows if r.footprint_iou is not None]
    if not rows:
        return chart("chart-iou", None, empty="no footprint IoU to chart")
    fig = go.Figure()
    series = sorted({(r.method, r.protocol) for r in rows},
                    key=lambda s: (method_rank(s[0]), protocol_rank(s[1])))
    for k, (method, protocol) in enumerate(series):
        mine = [r for r in rows if (r.method, r.protocol) == (method, protocol)]
        fig.add_trace(go.Bar(x=[r.scene for r in mine], y=[r.footprint_iou for r in mine],
                             name=f"{method} ({protocol})", marker_color=colour(k)))
    fig.update_layout(barmode="group", yaxis={"range": [0, 1], "title": "footprint IoU"},
                      margin={"t": 30, "b": 40})
    return chart("chart-iou", fig.to_json(), height_px=320)


def provenance_footer(provenance: Mapping[str, Any]) -> dict[str, Any]:
    """The footer's context: code version, time, data, the runs' status, each method's
    configuration and budget, and the libraries."""
    runs = provenance.get("runs", [])
    statuses: dict[str, int] = {}
    for run in runs:
        statuses[run.get("status", "?")] = statuses.get(run.get("status", "?"), 0) + 1
    libraries = next((r["provenance"].get("libraries") for r in runs
                      if r.get("provenance") and r["provenance"].get("libraries")), None)
    pairs = [("code version", provenance.get("code_version", "")),
             ("made (UTC)", provenance.get("created_utc", "")),
             ("data", provenance.get("data", "")),
             ("results", provenance.get("results", "")),
             ("runs", ", ".join(f"{n} {s}" for s, n in sorted(statuses.items())))]
    return {"provenance": pairs,
            "methods_json": json.dumps(provenance.get("methods", {}), indent=1, sort_keys=True),
            "libraries_json": json.dumps(libraries, sort_keys=True) if libraries
            else "not recorded"}


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m metrics.report.html_report",
        description="(Re)make report.html, one self-contained offline page with the tables, "
        "interactive charts, per-building details and the mesh viewer, from the output "
        "folder of `python -m metrics.compare`.")
    parser.add_argument("--out", type=Path, required=True,
                        help="the comparison's output folder (its --out); report.html goes there")
    args = parser.parse_args(argv)
    try:
        path = write_report(read_report_data(args.out))
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print(f"wrote {path} ({path.stat().st_size / 1e6:.1f} MB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
