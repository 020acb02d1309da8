"""Table 2 against both truths: the full facade and the facade seen straight on.

The full truth counts wall and glazing hidden behind railings, balconies and roof
overhangs; a method that measures what it sees cannot, and neural3d has a rule
that fills such wall in (``docs/neural3d-extract.md``). Each error is shown against
both, so a reader sees how much of a gap is that rule rather than reconstruction
(:mod:`dataset.families.visible_facade` defines "seen straight on").
"""

from __future__ import annotations

from collections.abc import Sequence

from metrics.report.tables import Table
from metrics.score.aggregate import GroupSummary
from metrics.score.bootstrap import INTERVAL_TEXT

TABLE2_VISIBLE_NAME = "table2_visible"
VISIBLE_NOTE = ("visible: against the facade seen straight on from in front (no wall or "
                "glazing hidden behind a railing, a balcony or an overhang); full: against "
                "all of it (the truth of Table 2)")


def table2_visible_errors(groups: Sequence[GroupSummary]) -> Table:
    """Per family, method and views: WWR, window and facade errors (%) against the full and
    the visible truth, side by side (groups without a visible truth show en dashes)."""
    rows = tuple(
        (g.family, g.method, g.protocol, g.buildings,
         g.wwr_ape, g.wwr_ape_visible, g.window_ape, g.window_ape_visible,
         g.facade_ape, g.facade_ape_visible)
        for g in groups
    )
    return Table(
        name=TABLE2_VISIBLE_NAME,
        title="Absolute percentage error (%) against the full and the visible facade truth, "
              f"mean ± std [{INTERVAL_TEXT}]",
        columns=("Family", "Method", "Views", "Buildings", "WWR, full", "WWR, visible",
                 "Window, full", "Window, visible", "Facade, full", "Facade, visible"),
        keys=("family", "method", "protocol", "buildings", "wwr_ape", "wwr_ape_visible",
              "window_ape", "window_ape_visible", "facade_ape", "facade_ape_visible"),
        rows=rows,
        notes=(VISIBLE_NOTE,),
    )
