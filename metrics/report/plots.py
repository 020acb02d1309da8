"""The comparison's plots, written as PNG and PDF (matplotlib, no pyplot state, Agg).

Each function raises ``ValueError`` when there is nothing to plot, so callers
can skip that plot with a message and make the others.
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from envelope.atomic import write_bytes_atomic
from envelope.results import code_version
from metrics.score.aggregate import GroupSummary, family_rank, method_rank, protocol_rank
from metrics.score.errors import BuildingErrors

PNG_DPI = 150
ERROR_PANELS = (("wwr_ape", "WWR error (%)"), ("window_ape", "Window error (%)"),
                ("facade_ape", "Facade error (%)"))


def save_figure(fig: Figure, stem: str | Path) -> list[Path]:
    """Write ``<stem>.png`` and ``<stem>.pdf`` atomically; returns both paths.

    Both files name the code version that made them in their metadata
    (PNG ``Software``, PDF ``Creator``).
    """
    stem = Path(stem)
    made_by = f"envelope-bench {code_version()}"
    paths = []
    for fmt, metadata in (("png", {"Software": made_by}), ("pdf", {"Creator": made_by})):
        buf = io.BytesIO()
        # Constrained layout already fits the labels: no tight-bbox pass needed.
        fig.savefig(buf, format=fmt, dpi=PNG_DPI, metadata=metadata)
        path = stem.with_name(f"{stem.name}.{fmt}")
        write_bytes_atomic(path, buf.getvalue())
        paths.append(path)
    return paths


def plot_errors_by_family(groups: Sequence[GroupSummary], stem: str | Path) -> list[Path]:
    """Grouped bars: one panel per error, families on x, one bar per (method, views), ± std."""
    groups = [g for g in groups if g.wwr_ape.count or g.window_ape.count or g.facade_ape.count]
    if not groups:
        raise ValueError("no errors to plot: every run failed or no run has ground truth")
    families = sorted({g.family for g in groups}, key=family_rank)
    series = sorted({(g.method, g.protocol) for g in groups},
                    key=lambda s: (method_rank(s[0]), protocol_rank(s[1])))
    by_key = {(g.family, g.method, g.protocol): g for g in groups}
    fig = Figure(figsize=(4.0 * len(ERROR_PANELS), 3.4), layout="constrained")
    axes = fig.subplots(1, len(ERROR_PANELS))
    width = 0.8 / len(series)
    x = np.arange(len(families))
    for ax, (attr, label) in zip(axes, ERROR_PANELS):
        for k, (method, protocol) in enumerate(series):
            stats = [getattr(by_key[(f, method, protocol)], attr)
                     if (f, method, protocol) in by_key else None for f in families]
            means = [s.mean if s and s.mean is not None else np.nan for s in stats]
            stds = [s.std if s and s.std is not None else 0.0 for s in stats]
            ax.bar(x + (k - (len(series) - 1) / 2) * width, means, width, yerr=stds,
                   capsize=2, label=f"{method} ({protocol})")
        ax.set_xticks(x, families, rotation=20)
        ax.set_ylabel(label)
        ax.set_ylim(bottom=0)
        ax.grid(axis="y", alpha=0.3)
    axes[0].legend(fontsize="small")
    return save_figure(fig, stem)


def plot_wwr_scatter(rows: Sequence[BuildingErrors], stem: str | Path) -> list[Path]:
    """Estimated vs true WWR, one panel per method, one marker per views protocol."""
    rows = [r for r in rows if r.wwr_est is not None and r.wwr_true is not None]
    if not rows:
        raise ValueError("no WWR estimate with ground truth to plot")
    methods = sorted({r.method for r in rows}, key=method_rank)
    fig = Figure(figsize=(3.4 * len(methods), 3.4), layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, len(methods)))
    top = max(max(r.wwr_est, r.wwr_true) for r in rows) * 1.1
    for ax, method in zip(axes, methods):
        mine = [r for r in rows if r.method == method]
        for protocol, marker in zip(sorted({r.protocol for r in mine}, key=protocol_rank),
                                    "os^Dv"):
            pts = [r for r in mine if r.protocol == protocol]
            ax.scatter([r.wwr_true for r in pts], [r.wwr_est for r in pts], marker=marker,
                       label=protocol, alpha=0.8)
        ax.plot([0, top], [0, top], color="grey", lw=0.8, ls="--")
        ax.set(xlim=(0, top), ylim=(0, top), xlabel="true WWR", ylabel="estimated WWR",
               title=method, aspect="equal")
        ax.legend(fontsize="small")
    return save_figure(fig, stem)


def plot_iou_per_building(rows: Sequence[BuildingErrors], stem: str | Path) -> list[Path]:
    """Footprint IoU per building, one bar per (method, views) that has a footprint."""
    rows = [r for r in rows if r.footprint_iou is not None]
    if not rows:
        raise ValueError("no footprint IoU to plot: no method estimated a footprint")
    scenes = sorted({(r.family, r.scene) for r in rows}, key=lambda s: (family_rank(s[0]), s[1]))
    series = sorted({(r.method, r.protocol) for r in rows},
                    key=lambda s: (method_rank(s[0]), protocol_rank(s[1])))
    iou = {(r.scene, r.method, r.protocol): r.footprint_iou for r in rows}
    fig = Figure(figsize=(max(4.0, 0.7 * len(scenes) + 2), 3.2), layout="constrained")
    ax = fig.subplots()
    width = 0.8 / len(series)
    x = np.arange(len(scenes))
    for k, (method, protocol) in enumerate(series):
        values = [iou.get((s, method, protocol), np.nan) for _, s in scenes]
        ax.bar(x + (k - (len(series) - 1) / 2) * width, values, width,
               label=f"{method} ({protocol})")
    ax.set_xticks(x, [s for _, s in scenes], rotation=30, ha="right")
    ax.set(ylim=(0, 1), ylabel="footprint IoU")
    ax.grid(axis="y", alpha=0.3)
    ax.legend(fontsize="small", loc="lower right")
    return save_figure(fig, stem)
