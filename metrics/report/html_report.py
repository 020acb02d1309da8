"""``python -m metrics.report.html_report --out DIR``: a comparison as one self-contained
``report.html``.

Reads what :mod:`metrics.compare` wrote to its output folder (the tables'
CSVs, ``per_building.csv``, ``provenance.json``, ``footprints/``,
``2dss_pipeline/``, ``<method>_runs.json``) and the scenes named in the
provenance, and writes ``report.html`` there: plotly.js and every image are
embedded, so the file opens offline and can be sent on its own.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence
from pathlib import Path

from envelope.atomic import write_text_atomic
from envelope.footprint import geojson_to_polygon
from envelope.protocols import IDEAL_PROTOCOL
from envelope.semantic_ply import read_semantic_ply
from metrics.report.html_claims import claims_sections
from metrics.report.html_orientation import orientation_section
from metrics.report.html_sections import (
    PAGE_CSS,
    PAGE_JS,
    Cell,
    chart,
    details_list,
    esc,
    family_filter,
    footprint_svg,
    image_tag,
    mesh_figure_json,
    sortable_table,
)
from metrics.report.mesh_decimate import decimate_vertex_clustering
from metrics.report.paper_tables import (
    CAVEATS,
    PAPER_KEYS,
    PAPER_TABLE2_LABEL,
    PAPER_TABLE3_LABEL,
)
from metrics.report.report import (
    PER_BUILDING_NAME,
    TABLE2_NAME,
    TABLE3_NAME,
    read_building_errors_csv,
)
from metrics.report.report_paper import PAPER_TABLE2_NAME, PAPER_TABLE3_NAME
from metrics.report.tables import format_cell, read_csv_rows, read_summary
from metrics.run.mesh_pointers import MeshRun, read_mesh_pointers
from metrics.score.aggregate import Summary, family_rank, method_rank, protocol_rank
from metrics.score.bootstrap import INTERVAL_TEXT
from metrics.score.errors import BuildingErrors

REPORT_FILE = "report.html"
MAX_MESH_FACES = 20_000  # plotly's mesh3d stays smooth in a browser well beyond this
ERROR_COLUMNS = (("wwr_ape", "WWR error (%)"), ("window_ape", "Window error (%)"),
                 ("facade_ape", "Facade error (%)"))


def write_report(out_dir: Path) -> Path:
    """Build ``out_dir/report.html`` from a comparison's outputs (atomically); returns its path.

    Raises
    ------
    ValueError
        If ``out_dir`` lacks the comparison's tables or provenance.
    """
    path = out_dir / REPORT_FILE
    write_text_atomic(path, build_report(out_dir))
    return path


def build_report(out_dir: Path) -> str:
    """The report's HTML text (see the module docstring for what it reads)."""
    from plotly.offline import get_plotlyjs

    for name in (f"{TABLE2_NAME}.csv", f"{TABLE3_NAME}.csv", f"{PER_BUILDING_NAME}.csv",
                 "provenance.json"):
        if not (out_dir / name).is_file():
            raise ValueError(f"{out_dir / name} does not exist; run `python -m metrics.compare "
                             f"--out {out_dir}` first")
    provenance = json.loads((out_dir / "provenance.json").read_text())
    table2 = read_csv_rows((out_dir / f"{TABLE2_NAME}.csv").read_text())
    table3 = read_csv_rows((out_dir / f"{TABLE3_NAME}.csv").read_text())
    paper2, paper3 = (_csv_rows_if_any(out_dir / f"{n}.csv")
                      for n in (PAPER_TABLE2_NAME, PAPER_TABLE3_NAME))
    rows = read_building_errors_csv(out_dir / f"{PER_BUILDING_NAME}.csv")
    scenes = sorted({(r.family, r.scene) for r in rows}, key=lambda s: (family_rank(s[0]), s[1]))
    data = Path(provenance.get("data", ""))
    nav = "".join(f'<button data-scene="{esc(s)}">{esc(s)} ({esc(f)})</button>'
                  for f, s in scenes)
    buildings = "".join(building_section(s, [r for r in rows if r.scene == s], data, out_dir)
                        for _, s in scenes)
    body = (
        f"<h1>envelope-bench comparison</h1><p>{esc(provenance.get('produced_by', ''))}</p>"
        f'<div id="overview"><h2>Table 2: errors per family</h2>{table2_html(table2, paper2)}'
        f"<h2>Table 3: footprint IoU</h2>{table3_html(table3, paper3)}"
        f"{claims_sections(out_dir)}"
        f"<h2>Charts</h2>{errors_chart(table2)}{iou_chart(rows)}"
        f"{orientation_section(out_dir)}</div>"
        f'<h2>Buildings</h2><p>Click a building to see its details.</p>'
        f'<nav class="buildings">{nav}</nav>{buildings}{provenance_footer(provenance)}'
    )
    return (f'<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">'
            f"<title>envelope-bench report</title><style>{PAGE_CSS}</style>"
            f"<script>{get_plotlyjs()}</script><script>{PAGE_JS}</script></head>"
            f"<body>{body}</body></html>\n")


def _summary(row: dict[str, str], key: str) -> Summary:
    return read_summary(row, key)


def _csv_rows_if_any(path: Path) -> list[dict[str, str]]:
    return read_csv_rows(path.read_text()) if path.is_file() else []


def _by_row(rows: Sequence[dict[str, str]]) -> dict[tuple[str, str, str], dict[str, str]]:
    return {(r["family"], r["method"], r["protocol"]): r for r in rows}


# our Table 2 error key -> the column of the paper's figure in the paper comparison table
_PAPER_COLUMN = {"wwr_ape": "paper_wwr_ape", "window_ape": "paper_window_ape",
                 "facade_ape": "paper_wall_ape"}


def _summary_cell(s: Summary | None, decimals: int, css: str = "") -> Cell:
    if s is None or s.mean is None:
        return format_cell(None, decimals), ""
    return format_cell(s, decimals), repr(s.mean)


def table2_html(rows: Sequence[dict[str, str]],
                paper_rows: Sequence[dict[str, str]] = ()) -> str:
    """Table 2 from its CSV rows, the paper's published errors beside ours (``paper_rows``:
    the rows of the paper comparison table, :mod:`metrics.report.report_paper`)."""
    paper = _by_row(paper_rows)
    columns = ["Family", "Method", "Views", "Buildings", "Failed"]
    for key, label in ERROR_COLUMNS:
        paper_label = "Wall" if key == "facade_ape" else label.split(" (")[0]
        columns += [label, f"{paper_label}, {PAPER_TABLE2_LABEL}"]
    columns += ["Steps", "Marks"]
    cells = []
    for r in rows:
        ref = paper.get((r["family"], r["method"], r["protocol"]))
        row: list[Cell] = [(r[k], r[k]) for k in ("family", "method", "protocol", "buildings",
                                                   "failed")]
        for key, _ in ERROR_COLUMNS:
            row += [_summary_cell(_summary(r, key), 2),
                    _summary_cell(_summary(ref, _PAPER_COLUMN[key]) if ref else None, 2)]
        row += [(r["steps"] or "–", r["steps"]), (r["marks"] or "", r["marks"])]
        cells.append(row)
    attrs = [{"family": r["family"], "method": r["method"], "protocol": r["protocol"]}
             for r in rows]
    families = sorted({r["family"] for r in rows}, key=family_rank)
    return (family_filter("table2", families) + sortable_table("table2", columns, cells, attrs)
            + f'<p class="ref">{esc(PAPER_TABLE2_LABEL)}: the published figures beside ours '
              f"({esc(', '.join(PAPER_KEYS))}; the paper's third column is the wall area's "
              "error), mean ± std over its four buildings of each type; ours: mean ± std "
              f"[{esc(INTERVAL_TEXT)}]; columns sort on click.</p>"
            + '<ul class="ref">' + "".join(f"<li>{esc(c)}</li>" for c in CAVEATS) + "</ul>")


def table3_html(rows: Sequence[dict[str, str]],
                paper_rows: Sequence[dict[str, str]] = ()) -> str:
    """Table 3 from its CSV rows, BuildNet3D's published IoU beside ours (``paper_rows``: the
    rows of the paper comparison table, :mod:`metrics.report.report_paper`)."""
    paper = _by_row(paper_rows)
    if not rows:
        return '<p class="muted">no method estimates a footprint</p>'
    columns = ["Family", "Method", "Views", "Buildings", "Failed", "Footprint IoU",
               f"IoU, {PAPER_TABLE3_LABEL}", "Steps", "Marks"]
    cells = [[(r[k], r[k]) for k in ("family", "method", "protocol", "buildings", "failed")]
             + [_summary_cell(_summary(r, "footprint_iou"), 3),
                _summary_cell(_paper_iou(paper.get((r["family"], r["method"], r["protocol"]))), 3),
                (r["steps"] or "–", r["steps"]), (r["marks"] or "", r["marks"])] for r in rows]
    attrs = [{"family": r["family"], "method": r["method"], "protocol": r["protocol"]}
             for r in rows]
    return (sortable_table("table3", columns, cells, attrs)
            + f'<p class="ref">{esc(PAPER_TABLE3_LABEL)}: BuildNet3D\'s mean over its four '
              "buildings of each type (no std published).</p>")


def _paper_iou(row: dict[str, str] | None) -> Summary | None:
    return None if row is None else _summary(row, "paper_footprint_iou")


def errors_chart(rows: Sequence[dict[str, str]]) -> str:
    """Table 2 as grouped bars (family on x, a bar per method and views, ± std), per error."""
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    fig = make_subplots(rows=1, cols=len(ERROR_COLUMNS),
                        subplot_titles=[label for _, label in ERROR_COLUMNS])
    series = sorted({(r["method"], r["protocol"]) for r in rows},
                    key=lambda s: (method_rank(s[0]), protocol_rank(s[1])))
    for k, (method, protocol) in enumerate(series):
        mine = sorted((r for r in rows if (r["method"], r["protocol"]) == (method, protocol)),
                      key=lambda r: family_rank(r["family"]))
        for col, (key, _) in enumerate(ERROR_COLUMNS, start=1):
            stats = [_summary(r, key) for r in mine]
            fig.add_trace(go.Bar(
                x=[r["family"] for r in mine], y=[s.mean for s in stats],
                error_y={"type": "data", "array": [s.std for s in stats]},
                name=f"{method} ({protocol})", legendgroup=f"{method}{protocol}",
                showlegend=col == 1, marker_color=_colour(k)), row=1, col=col)
    fig.update_layout(barmode="group", margin={"t": 40, "b": 40})
    return chart("chart-errors", fig.to_json())


def iou_chart(rows: Sequence[BuildingErrors]) -> str:
    """Footprint IoU per building, one bar per method and views."""
    import plotly.graph_objects as go

    rows = [r for r in rows if r.footprint_iou is not None]
    if not rows:
        return '<p class="muted">no footprint IoU to chart</p>'
    fig = go.Figure()
    series = sorted({(r.method, r.protocol) for r in rows},
                    key=lambda s: (method_rank(s[0]), protocol_rank(s[1])))
    for k, (method, protocol) in enumerate(series):
        mine = [r for r in rows if (r.method, r.protocol) == (method, protocol)]
        fig.add_trace(go.Bar(x=[r.scene for r in mine], y=[r.footprint_iou for r in mine],
                             name=f"{method} ({protocol})", marker_color=_colour(k)))
    fig.update_layout(barmode="group", yaxis={"range": [0, 1], "title": "footprint IoU"},
                      margin={"t": 30, "b": 40})
    return chart("chart-iou", fig.to_json(), height_px=320)


def _colour(k: int) -> str:
    from metrics.report.html_sections import METHOD_COLOURS

    return METHOD_COLOURS[k % len(METHOD_COLOURS)]


def _number(value: float | None, fmt: str) -> str:
    return "–" if value is None else format(value, fmt)


def building_section(scene: str, rows: Sequence[BuildingErrors], data: Path,
                     out_dir: Path) -> str:
    """One building: truth, each method's estimates and errors, images, footprints, mesh."""
    scene_dir = data / scene if (data / scene).is_dir() else data
    first = rows[0]
    truth = details_list([("family", first.family),
                          ("WWR", _number(first.wwr_true, ".4f")),
                          ("window area (m²)", _number(first.window_true_m2, ".2f")),
                          ("facade area (m²)", _number(first.facade_true_m2, ".2f"))])
    columns = ["Method", "Views", "Status", "WWR", "WWR error (%)", "Window (m²)",
               "Window error (%)", "Facade (m²)", "Facade error (%)", "Footprint IoU",
               "Why / marks"]
    cells = []
    for r in sorted(rows, key=lambda r: (method_rank(r.method), protocol_rank(r.protocol))):
        values = [(r.wwr_est, ".4f"), (r.wwr_ape, ".2f"), (r.window_est_m2, ".2f"),
                  (r.window_ape, ".2f"), (r.facade_est_m2, ".2f"), (r.facade_ape, ".2f"),
                  (r.footprint_iou, ".3f")]
        note = "; ".join(x for x in (r.reason, r.marks) if x)
        cells.append([(r.method, r.method), (r.protocol, r.protocol), (r.status, r.status)]
                     + [(_number(v, fmt), "" if v is None else repr(v)) for v, fmt in values]
                     + [(note, note)])
    attrs = [{"status": r.status} for r in rows]
    estimates = sortable_table(f"est-{scene}", columns, cells, attrs).replace(
        '<tr data-status="failed">', '<tr data-status="failed" class="failed">')
    images = "".join(_images(scene, scene_dir, out_dir))
    return (f'<section class="building" data-scene="{esc(scene)}" hidden><h3>{esc(scene)}</h3>'
            f'<div class="row"><div><h4>Truth</h4>{truth}</div>'
            f"<div><h4>Footprints</h4>{_footprints(scene, scene_dir, out_dir)}</div></div>"
            f"<h4>Estimates</h4>{estimates}<div class=\"row\">{images}</div>"
            f"{_mesh_viewer(scene, out_dir)}</section>")


def _images(scene: str, scene_dir: Path, out_dir: Path) -> list[str]:
    """The first ideal view's image and the 2D-SS pipeline images kept for this scene."""
    out = []
    transforms = scene_dir / "transforms.json"
    if transforms.is_file():
        frames = json.loads(transforms.read_text()).get("frames", [])
        ideal = [f for f in frames if f.get("split") == IDEAL_PROTOCOL] or frames[:1]
        if ideal and (scene_dir / ideal[0]["file_path"]).is_file():
            out.append(image_tag(scene_dir / ideal[0]["file_path"], "render (first ideal view)"))
    for png in sorted((out_dir / "2dss_pipeline").glob(f"{scene}__*.png")):
        out.append(image_tag(png, "2D-SS: " + png.stem.split("__")[-1]))
    return out


def _footprints(scene: str, scene_dir: Path, out_dir: Path) -> str:
    truth = None
    building = scene_dir / "building.json"
    try:
        if building.is_file():
            truth = geojson_to_polygon(json.loads(building.read_text())["footprint"])
        estimates = [(p.stem.split("__", 1)[1].replace("__", " "),
                      geojson_to_polygon(json.loads(p.read_text())))
                     for p in sorted((out_dir / "footprints").glob(f"{scene}__*.geojson"))]
    except (ValueError, KeyError) as exc:
        return f'<p class="muted">footprints unreadable: {esc(exc)}</p>'
    return footprint_svg(truth, estimates)


def _mesh_viewer(scene: str, out_dir: Path) -> str:
    """The semantic meshes of ``scene`` (decimated; each ``<method>_runs.json``), drawn
    when the building is opened."""
    return "".join(_one_mesh(run, i) for i, run in enumerate(
        r for r in read_mesh_pointers(out_dir) if r.scene == scene))


def _one_mesh(run: MeshRun, index: int) -> str:
    try:
        vertices, faces, labels, _ = read_semantic_ply(run.mesh)
    except ValueError as exc:
        return f'<p class="muted">{esc(run.method)} mesh unreadable: {esc(exc)}</p>'
    n_faces = len(faces)
    vertices, faces, labels = decimate_vertex_clustering(vertices, faces, labels, MAX_MESH_FACES)
    title = f"{run.method} semantic mesh ({len(faces)} of {n_faces} faces)"
    chart_id = f"mesh-{run.scene}" + (f"-{index}" if index else "")
    return (f'<h4>{esc(run.method)} mesh</h4><div class="mesh-wrap">'
            f'{chart(chart_id, mesh_figure_json(vertices, faces, labels, title), 460)}'
            f"</div>")


def provenance_footer(provenance: dict) -> str:
    """Code version, time, data, each method's configuration and budget, and the runs' status."""
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
    methods = json.dumps(provenance.get("methods", {}), indent=1, sort_keys=True)
    libs = json.dumps(libraries, sort_keys=True) if libraries else "not recorded"
    return (f"<footer><h2>Provenance</h2>{details_list(pairs)}"
            f"<h4>Methods: configuration, budgets, device</h4><pre>{esc(methods)}</pre>"
            f"<h4>Libraries</h4><pre>{esc(libs)}</pre></footer>")


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
        path = write_report(args.out)
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print(f"wrote {path} ({path.stat().st_size / 1e6:.1f} MB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
