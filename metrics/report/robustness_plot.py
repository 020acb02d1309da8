"""The robustness study's rows (:class:`RobustnessRow`) and its plot: error against severity,
one panel per degradation, one curve per method and views (style and file handling of
:mod:`metrics.report.plots`)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from metrics.report.plots import save_figure
from metrics.score.aggregate import method_rank, protocol_rank

MARKERS = "osD^v<>"
"""One marker per curve (method and views), repeated past the seventh (both 2D methods on
four protocols and neural3d on two make ten)."""
SEVERITY_UNITS = {
    "mask_noise": "level", "occluders": "occluders per facade", "pose": "degrees",
    "depth_noise": "level", "mask_erode": "px", "mask_dilate": "px", "mask_bleed": "px",
    "mask_miss": "probability", "mask_false": "probability",
}


@dataclass(frozen=True)
class RobustnessRow:
    """Mean errors (APE, %) of one method and views under one degradation and severity."""

    degradation: str
    severity: float
    method: str
    protocol: str
    buildings: int
    failed: int
    wwr_ape: float | None
    window_ape: float | None
    facade_ape: float | None


def plot_robustness(rows: Sequence[RobustnessRow], stem: str | Path,
                    attr: str = "wwr_ape", label: str = "WWR error (%)") -> list[Path]:
    """Mean ``attr`` against severity; raises ``ValueError`` when there is nothing to plot."""
    rows = [r for r in rows if getattr(r, attr) is not None]
    if not rows:
        raise ValueError("no robustness errors to plot: every run failed")
    degradations = list(dict.fromkeys(r.degradation for r in rows))
    series = sorted({(r.method, r.protocol) for r in rows},
                    key=lambda s: (method_rank(s[0]), protocol_rank(s[1])))
    fig = Figure(figsize=(3.4 * len(degradations), 3.4), layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, len(degradations)))
    for ax, name in zip(axes, degradations):
        for k, (method, protocol) in enumerate(series):
            marker = MARKERS[k % len(MARKERS)]  # cycled: no series is left out
            pts = sorted((r.severity, getattr(r, attr)) for r in rows
                         if r.degradation == name and r.method == method
                         and r.protocol == protocol)
            if pts:
                ax.plot(*zip(*pts), marker=marker, label=f"{method} ({protocol})")
        ax.set(title=name, xlabel=f"severity ({SEVERITY_UNITS.get(name, 'level')})")
        ax.set_ylim(bottom=0)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel(label)
    axes[0].legend(fontsize="small")
    return save_figure(fig, stem)
