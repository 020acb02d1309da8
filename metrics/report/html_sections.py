"""The report's pieces that are not markup: table cells, plotly figures, footprint outlines,
embedded images; and the small sections made of one template each (a chart, the footprints).

The markup itself is in ``templates/`` (:mod:`metrics.report.templating`, autoescaped).
Charts are plotly figures serialised to JSON and drawn by the page's embedded plotly.js;
the mesh figure is drawn when its building is first opened.
"""

from __future__ import annotations

import base64
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from markupsafe import Markup
from shapely.geometry import MultiPolygon, Polygon

from envelope.classes import CLASS_NAMES, CLASS_RGB, UNKNOWN_CLASS_RGB
from metrics.report.tables import Cell as TableCell
from metrics.report.tables import format_cell
from metrics.report.templating import render
from metrics.score.aggregate import Summary

SVG_SIZE_PX = 320
SVG_MARGIN_PX = 10
TRUTH_COLOUR = "#222222"
METHOD_COLOURS = ("#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b")

Cell = tuple[str, str]  # (display text, sort key: a number as text, or the text itself)


def label_cell(value: TableCell) -> Cell:
    """A label or count as it is (``–`` for none), sorted on its text."""
    text = "" if value is None else str(value)
    return text or "–", text


def summary_cell(value: TableCell, decimals: int) -> Cell:
    """``mean ± std [low, high]`` of a summary (``–`` for none), sorted on the mean."""
    if not isinstance(value, Summary) or value.mean is None:
        return format_cell(None, decimals), ""
    return format_cell(value, decimals), repr(value.mean)


def number_cell(value: float | None, fmt: str) -> Cell:
    """A number in format ``fmt`` (``–`` for none), sorted on its full value."""
    return ("–", "") if value is None else (format(value, fmt), repr(value))


def colour(k: int) -> str:
    """The ``k``-th series' colour (method and views), cycling."""
    return METHOD_COLOURS[k % len(METHOD_COLOURS)]


def chart(div_id: str, figure_json: str | None, height_px: int = 380,
          empty: str = "nothing to chart") -> Markup:
    """A div that plotly draws from ``figure_json`` (``plotly.graph_objects.Figure.to_json``),
    or the note ``empty`` when there is no figure."""
    return render("chart.html.j2", div_id=div_id, figure_json=figure_json,
                  height_px=height_px, empty=empty)


def png_base64(path: Path) -> str:
    """The PNG at ``path`` as base64 text, for a ``data:`` URL."""
    return base64.b64encode(path.read_bytes()).decode("ascii")


def footprint_svg(truth: Polygon | MultiPolygon | None,
                  estimates: Sequence[tuple[str, Polygon | MultiPolygon]]) -> Markup:
    """Inline SVG: the true footprint (dark, filled) and each estimate's outline, with a legend.

    Polygons are in world x/y metres; the SVG keeps their aspect ratio, +y up.
    """
    labelled = ([("truth", truth, TRUTH_COLOUR)] if truth is not None else []) + [
        (label, shape, colour(k)) for k, (label, shape) in enumerate(estimates)]
    if not labelled:
        return render("footprint.html.j2", shapes=[])
    bounds = np.array([s.bounds for _, s, _ in labelled])
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

    shapes = [{"label": label, "path": path(shape), "colour": c,
               "truth": truth is not None and k == 0}
              for k, (label, shape, c) in enumerate(labelled)]
    return render("footprint.html.j2", shapes=shapes, size_px=SVG_SIZE_PX, span_m=span_m)


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
