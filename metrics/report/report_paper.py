"""Our Tables 2 and 3 beside the BuildNet3D paper's published figures
(:mod:`metrics.report.paper_tables`).

One row per (family, method, views) the paper also reports; each of our figures
(mean ± std [interval]) stands next to the paper's (mean ± std; Table 3: mean),
and the notes say what differs in a like-for-like reading.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from metrics.report.paper_tables import (
    CAVEATS,
    PAPER_TABLE2_LABEL,
    PAPER_TABLE3_LABEL,
    paper_table2,
    paper_table3,
)
from metrics.report.tables import Table
from metrics.score.aggregate import GroupSummary

PAPER_TABLE2_NAME = "paper_table2"
PAPER_TABLE3_NAME = "paper_table3"


def paper_table2_comparison(groups: Sequence[GroupSummary],
                            paper_names: Mapping[str, str]) -> Table:
    """Our errors beside the paper's Table 2, for every group the paper has a row for
    (``paper_names``: our method's name -> its name in the paper)."""
    rows = []
    for g in groups:
        paper = paper_table2(g.family, paper_names.get(g.method), g.protocol)
        if paper is not None:
            rows.append((g.family, g.method, g.protocol, g.buildings, g.steps,
                         g.wwr_ape, paper["wwr_ape"], g.window_ape, paper["window_ape"],
                         g.facade_ape, paper["facade_ape"]))
    return Table(
        name=PAPER_TABLE2_NAME,
        title=f"Absolute percentage error (%), ours beside the {PAPER_TABLE2_LABEL}",
        columns=("Family", "Method", "Views", "Buildings", "Steps", "WWR, ours",
                 f"WWR, {PAPER_TABLE2_LABEL}", "Window, ours", f"Window, {PAPER_TABLE2_LABEL}",
                 "Facade, ours", f"Wall, {PAPER_TABLE2_LABEL}"),
        keys=("family", "method", "protocol", "buildings", "steps", "wwr_ape", "paper_wwr_ape",
              "window_ape", "paper_window_ape", "facade_ape", "paper_wall_ape"),
        rows=tuple(rows),
        notes=tuple(f"like for like: {c}" for c in CAVEATS),
    )


def paper_table3_comparison(groups: Sequence[GroupSummary],
                            paper_names: Mapping[str, str]) -> Table:
    """Our footprint IoU beside the paper's Table 3 (BuildNet3D's rows only; ``paper_names``:
    our method's name -> its name in the paper)."""
    rows = []
    for g in groups:
        paper = paper_table3(g.family, paper_names.get(g.method), g.protocol)
        if paper is not None:
            rows.append((g.family, g.method, g.protocol, g.buildings, g.steps, g.footprint_iou,
                         paper))
    return Table(
        name=PAPER_TABLE3_NAME,
        title=f"Footprint IoU, ours beside the {PAPER_TABLE3_LABEL}",
        columns=("Family", "Method", "Views", "Buildings", "Steps", "IoU, ours",
                 f"IoU, {PAPER_TABLE3_LABEL}"),
        keys=("family", "method", "protocol", "buildings", "steps", "footprint_iou",
              "paper_footprint_iou"),
        rows=tuple(rows),
        notes=tuple(f"like for like: {c}" for c in CAVEATS if "wall" not in c),
        decimals=3,
    )
