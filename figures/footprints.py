"""Footprint overlays: the true footprint against each method's estimate, per building.

Reads the estimates that ``metrics.compare`` copies into ``footprints/``
(``<scene>__<method>__<protocol>.geojson``) and the truth from each scene's building.json.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from shapely.geometry import MultiPolygon, Polygon

from envelope.footprint import geojson_to_polygon
from envelope.truth import BuildingTruth
from figures.style import MissingInput
from metrics.report.plots import save_figure
from metrics.score.errors import footprint_iou


def footprint_pairs(
    truths: Sequence[tuple[Path, BuildingTruth]], folder: Path
) -> list[tuple[str, str, Polygon | MultiPolygon, Polygon | MultiPolygon]]:
    """(scene, method label, truth, estimate) for every estimated footprint of a known scene."""
    by_scene = {d.name: t for d, t in truths}
    pairs = []
    for path in sorted(folder.glob("*.geojson")) if folder.is_dir() else []:
        scene, method, protocol = path.stem.rsplit("__", 2)
        if scene not in by_scene:
            continue
        try:
            estimate = geojson_to_polygon(json.loads(path.read_text()))
        except ValueError:
            continue
        truth = geojson_to_polygon(by_scene[scene].footprint)
        pairs.append((scene, f"{method} ({protocol})", truth, estimate))
    if not pairs:
        raise MissingInput(f"no estimated footprint in {folder} for a scene with ground truth")
    return pairs


def plot_footprint_overlays(pairs: Sequence[tuple], stem: str | Path) -> list[Path]:
    """One panel per (building, method): truth filled grey, estimate outlined red, IoU in title."""
    cols = min(4, len(pairs))
    nrows = -(-len(pairs) // cols)
    fig = Figure(figsize=(2.8 * cols, 2.9 * nrows), layout="constrained")
    axes = np.atleast_1d(fig.subplots(nrows, cols)).ravel()
    for ax, (scene, label, truth, estimate) in zip(axes, pairs):
        for poly in _parts(truth):
            ax.fill(*poly.exterior.xy, color="0.75", label="truth")
            for hole in poly.interiors:
                ax.fill(*hole.xy, color="white")
        for poly in _parts(estimate):
            ax.plot(*poly.exterior.xy, color="tab:red", lw=1.5, label="estimate")
            for hole in poly.interiors:
                ax.plot(*hole.xy, color="tab:red", lw=1.0)
        ax.set_title(f"{scene}\n{label}: IoU {footprint_iou(truth, estimate):.3f}",
                     fontsize="small")
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)", fontsize="small")
        ax.tick_params(labelsize="x-small")
    for ax in axes[len(pairs):]:
        ax.set_visible(False)
    handles, labels = axes[0].get_legend_handles_labels()
    unique = dict(zip(labels, handles))
    axes[0].legend(unique.values(), unique.keys(), fontsize="x-small")
    return save_figure(fig, stem)


def _parts(poly: Polygon | MultiPolygon) -> list[Polygon]:
    return list(poly.geoms) if isinstance(poly, MultiPolygon) else [poly]
