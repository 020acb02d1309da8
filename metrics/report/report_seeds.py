"""How far repeated trainings of one building lie apart: the seed-to-seed spread per group.

A method trained from random weights (neural3d) gives another figure with another
seed. The tables count each building once (its seeds averaged, :mod:`metrics.score.aggregate`);
this table says how much one training could have moved it.
"""

from __future__ import annotations

from collections.abc import Sequence

from metrics.report.tables import Table
from metrics.score.aggregate import GroupSummary

SEED_TABLE_NAME = "seed_spread"


def seed_spread_table(groups: Sequence[GroupSummary]) -> Table | None:
    """Per group with seeds: buildings, seeds per building and the seed-to-seed standard
    deviation (``ddof=1``) of the WWR error (percentage points) and of the footprint IoU,
    mean ± std over buildings; ``None`` when no group has two seeds on a building."""
    kept = [g for g in groups if g.seeds is not None and g.wwr_seed_sd.count]
    if not kept:
        return None
    return Table(
        name=SEED_TABLE_NAME,
        title="Seed-to-seed spread of one building's figures (std over its seeds, ddof=1), "
              "mean ± std over buildings [bootstrap interval]",
        columns=("Family", "Method", "Views", "Buildings", "Seeds", "WWR error SD (pp)",
                 "Footprint IoU SD"),
        keys=("family", "method", "protocol", "buildings", "seeds", "wwr_seed_sd",
              "iou_seed_sd"),
        rows=tuple((g.family, g.method, g.protocol, g.buildings, g.seeds, g.wwr_seed_sd,
                    g.iou_seed_sd) for g in kept),
        decimals=3,
    )
