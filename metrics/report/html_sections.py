"""HTML pieces of the report: sortable tables, plotly charts, footprint SVGs, images, a mesh viewer.

Every function returns a string of HTML (escaped where it holds data) and
reads nothing from disk except :func:`image_tag`, which embeds a PNG as base64.
Charts are plotly figures serialised to JSON and drawn by the page's embedded
plotly.js; the mesh figure is drawn when its building is first opened.
"""

from __future__ import annotations

import base64
import html
import json
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from shapely.geometry import MultiPolygon, Polygon

from envelope.classes import CLASS_NAMES, CLASS_RGB, UNKNOWN_CLASS_RGB

SVG_SIZE_PX = 320
SVG_MARGIN_PX = 10
TRUTH_COLOUR = "#222222"
METHOD_COLOURS = ("#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b")

Cell = tuple[str, str]  # (display text, sort key: a number as text, or the text itself)


def esc(text: object) -> str:
    """HTML-escaped ``str(text)``."""
    return html.escape(str(text), quote=True)


def sortable_table(table_id: str, columns: Sequence[str], rows: Sequence[Sequence[Cell]],
                   row_attrs: Sequence[dict[str, str]] | None = None) -> str:
    """A ``<table class="sortable">`` whose header cells sort by each cell's ``data-sort``."""
    head = "".join(f"<th>{esc(c)}</th>" for c in columns)
    body = []
    for i, row in enumerate(rows):
        attrs = "".join(f' data-{k}="{esc(v)}"' for k, v in (row_attrs[i] if row_attrs else {})
                        .items())
        cells = "".join(f'<td data-sort="{esc(key)}">{esc(text)}</td>' for text, key in row)
        body.append(f"<tr{attrs}>{cells}</tr>")
    return (f'<table id="{esc(table_id)}" class="sortable"><thead><tr>{head}</tr></thead>'
            f'<tbody>{"".join(body)}</tbody></table>')


def json_for_script(obj: object) -> str:
    """JSON safe inside a ``<script>`` element (no ``</`` sequence)."""
    return json.dumps(obj, separators=(",", ":")).replace("</", "<\\/")


def chart(div_id: str, figure_json: str, height_px: int = 380) -> str:
    """A div that plotly draws from ``figure_json`` (``plotly.graph_objects.Figure.to_json``)."""
    payload = figure_json.replace("</", "<\\/")
    return (f'<div id="{esc(div_id)}" class="chart" style="height:{height_px}px"></div>'
            f'<script type="application/json" data-chart="{esc(div_id)}">{payload}</script>')


def image_tag(path: Path, caption: str, *, width_px: int = 240) -> str:
    """A ``<figure>`` holding the PNG at ``path`` as a base64 data URL."""
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    return (f'<figure><img src="data:image/png;base64,{data}" width="{width_px}" '
            f'alt="{esc(caption)}"><figcaption>{esc(caption)}</figcaption></figure>')


def footprint_svg(truth: Polygon | MultiPolygon | None,
                  estimates: Sequence[tuple[str, Polygon | MultiPolygon]]) -> str:
    """Inline SVG: the true footprint (dark, filled) and each estimate's outline, with a legend.

    Polygons are in world x/y metres; the SVG keeps their aspect ratio, +y up.
    """
    shapes = ([truth] if truth is not None else []) + [p for _, p in estimates]
    if not shapes:
        return '<p class="muted">no footprint</p>'
    bounds = np.array([s.bounds for s in shapes])
    x0, y0 = bounds[:, 0].min(), bounds[:, 1].min()
    span_m = max(bounds[:, 2].max() - x0, bounds[:, 3].max() - y0, 1e-9)
    scale = (SVG_SIZE_PX - 2 * SVG_MARGIN_PX) / span_m

    def path(shape: Polygon | MultiPolygon) -> str:
        parts = []
        for poly in getattr(shape, "geoms", [shape]):
            for ring in (poly.exterior, *poly.interiors):
                pts = " L".join(f"{SVG_MARGIN_PX + (x - x0) * scale:.1f},"
                                f"{SVG_SIZE_PX - SVG_MARGIN_PX - (y - y0) * scale:.1f}"
                                for x, y in ring.coords)
                parts.append(f"M{pts} Z")
        return " ".join(parts)

    items = []
    legend = []
    if truth is not None:
        items.append(f'<path d="{path(truth)}" fill="{TRUTH_COLOUR}" fill-opacity="0.25" '
                     f'stroke="{TRUTH_COLOUR}" stroke-width="2" fill-rule="evenodd"/>')
        legend.append(f'<span style="color:{TRUTH_COLOUR}">■ truth</span>')
    for k, (label, shape) in enumerate(estimates):
        colour = METHOD_COLOURS[k % len(METHOD_COLOURS)]
        items.append(f'<path d="{path(shape)}" fill="none" stroke="{colour}" stroke-width="2" '
                     f'stroke-dasharray="6 3" fill-rule="evenodd"/>')
        legend.append(f'<span style="color:{colour}">▭ {esc(label)}</span>')
    return (f'<figure class="footprint"><svg xmlns="http://www.w3.org/2000/svg" '
            f'width="{SVG_SIZE_PX}" height="{SVG_SIZE_PX}" viewBox="0 0 {SVG_SIZE_PX} '
            f'{SVG_SIZE_PX}">{"".join(items)}</svg><figcaption>{" ".join(legend)} '
            f"({span_m:.1f} m across)</figcaption></figure>")


def mesh_figure_json(vertices_m: np.ndarray, faces: np.ndarray, vertex_labels: np.ndarray,
                     title: str) -> str:
    """Plotly ``mesh3d`` figure JSON of a labelled mesh, vertices coloured by class.

    vertices_m : (V, 3) float, faces : (F, 3) int, vertex_labels : (V,) int class ids.
    Colours are :data:`envelope.classes.CLASS_RGB`; ids beyond it are magenta.
    """
    import plotly.graph_objects as go

    palette = np.array([*CLASS_RGB, UNKNOWN_CLASS_RGB])
    labels = np.minimum(np.asarray(vertex_labels, dtype=int), len(CLASS_RGB))
    colours = [f"rgb({r},{g},{b})" for r, g, b in palette[labels]]
    v = np.round(np.asarray(vertices_m, dtype=float), 3)
    f = np.asarray(faces, dtype=int)
    traces = [go.Mesh3d(x=v[:, 0], y=v[:, 1], z=v[:, 2], i=f[:, 0], j=f[:, 1], k=f[:, 2],
                        vertexcolor=colours, flatshading=True, hoverinfo="skip", name="mesh",
                        lighting={"ambient": 0.6, "diffuse": 0.6})]
    for cid in sorted(set(labels.tolist())):  # one legend entry per class present
        r, g, b = palette[cid]
        name = CLASS_NAMES[cid] if cid < len(CLASS_NAMES) else "unknown"
        traces.append(go.Scatter3d(x=[None], y=[None], z=[None], mode="markers", name=name,
                                   marker={"color": f"rgb({r},{g},{b})", "size": 8}))
    fig = go.Figure(traces)
    fig.update_layout(title=title, margin={"l": 0, "r": 0, "t": 30, "b": 0},
                      scene={"aspectmode": "data"}, showlegend=True)
    return fig.to_json()


def details_list(pairs: Sequence[tuple[str, str]]) -> str:
    """A ``<dl>`` of (term, value) pairs."""
    return "<dl>" + "".join(f"<dt>{esc(k)}</dt><dd>{esc(v)}</dd>" for k, v in pairs) + "</dl>"


PAGE_CSS = """
body{font-family:system-ui,sans-serif;margin:0 auto;max-width:1280px;padding:0 16px;color:#222}
h1{font-size:1.5em}h2{border-bottom:1px solid #ccc;padding-bottom:4px}
table.sortable{border-collapse:collapse;font-size:13px;margin:8px 0}
table.sortable th{cursor:pointer;background:#f0f0f0;user-select:none}
table.sortable th,table.sortable td{border:1px solid #ddd;padding:3px 6px;text-align:right}
table.sortable td:nth-child(-n+3){text-align:left}
td.failed,tr.failed td{background:#fde8e8}.ref{color:#666}.muted{color:#888}
nav.buildings button{margin:2px;padding:4px 10px;cursor:pointer}
nav.buildings button.active{background:#335;color:#fff}
section.building{border:1px solid #ccc;padding:8px;margin:8px 0}
.row{display:flex;flex-wrap:wrap;gap:12px;align-items:flex-start}
figure{margin:4px}figcaption{font-size:12px;color:#555}
.mesh{width:560px;height:460px}
dl{display:grid;grid-template-columns:max-content auto;gap:2px 12px;font-size:13px}
dt{font-weight:600}dd{margin:0}footer{font-size:12px;color:#555;margin:24px 0}
footer pre{white-space:pre-wrap;background:#f7f7f7;padding:6px}
"""

PAGE_JS = """
function drawCharts(root){root.querySelectorAll('script[data-chart]').forEach(function(s){
  var id=s.getAttribute('data-chart');var el=document.getElementById(id);
  if(el.dataset.drawn)return;var fig=JSON.parse(s.textContent);el.dataset.drawn='1';
  Plotly.newPlot(el,fig.data,fig.layout,{responsive:true,displaylogo:false});});}
function showBuilding(name){
  document.querySelectorAll('section.building').forEach(function(s){
    s.hidden=s.dataset.scene!==name;});
  document.querySelectorAll('nav.buildings button').forEach(function(b){
    b.classList.toggle('active',b.dataset.scene===name);});
  var sec=document.querySelector('section.building[data-scene="'+name+'"]');
  if(sec)drawCharts(sec);}
function sortTable(th){var table=th.closest('table');var body=table.tBodies[0];
  var col=Array.prototype.indexOf.call(th.parentNode.children,th);
  var asc=th.dataset.order!=='asc';th.dataset.order=asc?'asc':'desc';
  var rows=Array.prototype.slice.call(body.rows);
  rows.sort(function(a,b){var x=a.cells[col].dataset.sort,y=b.cells[col].dataset.sort;
    var nx=parseFloat(x),ny=parseFloat(y);
    var c=(isNaN(nx)||isNaN(ny))?String(x).localeCompare(String(y)):nx-ny;
    return asc?c:-c;});
  rows.forEach(function(r){body.appendChild(r);});}
function filterFamily(sel){var t=document.getElementById(sel.dataset.table);
  Array.prototype.forEach.call(t.tBodies[0].rows,function(r){
    r.hidden=sel.value!=='*'&&r.dataset.family!==sel.value;});}
document.addEventListener('DOMContentLoaded',function(){
  document.querySelectorAll('table.sortable th').forEach(function(th){
    th.addEventListener('click',function(){sortTable(th);});});
  document.querySelectorAll('nav.buildings button').forEach(function(b){
    b.addEventListener('click',function(){showBuilding(b.dataset.scene);});});
  document.querySelectorAll('select.family').forEach(function(s){
    s.addEventListener('change',function(){filterFamily(s);});});
  drawCharts(document.getElementById('overview'));});
"""


def family_filter(table_id: str, families: Sequence[str]) -> str:
    """A ``<select>`` that shows only one family's rows of ``table_id`` (or all)."""
    options = '<option value="*">every family</option>' + "".join(
        f'<option value="{esc(f)}">{esc(f)}</option>' for f in families)
    return (f'<label>Family: <select class="family" data-table="{esc(table_id)}">{options}'
            f"</select></label>")
