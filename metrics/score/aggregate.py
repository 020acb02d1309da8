"""Aggregation of per-building errors per building family: mean ± std, interval, count, failures.

A building trained with several seeds (neural3d's repeated trainings) counts once:
its seeds' errors are averaged first, then the family's buildings are summarised,
their mean with a bootstrap interval over buildings (:mod:`metrics.score.bootstrap`); how
far the seeds of one building lie apart is reported beside (``*_seed_sd``).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from envelope.method import BUILT_IN
from envelope.protocols import PROTOCOLS
from envelope.truth import BUILDING_TYPES
from metrics.score.bootstrap import bootstrap_interval
from metrics.score.errors import BuildingErrors

ALL_FAMILIES = "all"  # the family label of the row that pools every family
METHOD_ORDER = tuple(BUILT_IN)  # the built-in methods, in the order they are declared
PROTOCOL_ORDER = PROTOCOLS


@dataclass(frozen=True)
class Summary:
    """Mean and standard deviation of ``count`` values; both ``None`` when ``count`` is 0.

    The standard deviation is the population one (``ddof=0``), so a single
    building gives 0 rather than an undefined value. ``low``/``high``: the
    bootstrap interval of the mean (:data:`metrics.score.bootstrap.INTERVAL_TEXT`),
    ``None`` for fewer than two values or where not computed.
    """

    mean: float | None
    std: float | None
    count: int
    low: float | None = None
    high: float | None = None


def summarise(values: Iterable[float | None]) -> Summary:
    """Mean ± std and bootstrap interval of the values that are not ``None``.

    Raises
    ------
    ValueError
        If a value is NaN or infinite (a bug upstream, not a missing figure).
    """
    kept = [float(v) for v in values if v is not None]
    if any(not math.isfinite(v) for v in kept):
        raise ValueError(f"cannot summarise non-finite values {kept}; use None for a missing one")
    if not kept:
        return Summary(None, None, 0)
    arr = np.asarray(kept)
    interval = bootstrap_interval(arr)
    low, high = interval if interval is not None else (None, None)
    return Summary(float(arr.mean()), float(arr.std()), len(kept), low, high)


@dataclass(frozen=True)
class GroupSummary:
    """Errors of one (family, method, protocol) group.

    ``buildings`` counts the group's buildings, ``failed`` those with no result
    (from any seed); ``reasons`` holds ``"<scene>: <reason>"`` for each failed run.
    ``steps`` is the members' step budget (``"1000"``, a range ``"500–1000"``,
    or ``None`` for methods without one); ``marks`` counts the members'
    marks (``"cut short: 1; stale: 3"``, ``""`` for none). A building's seeds are
    averaged before the summaries; ``seeds`` is how many each building has
    (``"3"``, ``"2–3"``, ``None`` for methods without seeds) and ``wwr_seed_sd`` /
    ``iou_seed_sd`` summarise, over buildings with two seeds or more, the
    seed-to-seed standard deviation (``ddof=1``) of the WWR error (percentage points)
    and of the footprint IoU. ``*_visible``: errors against the facade seen straight on.
    """

    family: str
    method: str
    protocol: str
    buildings: int
    failed: int
    wwr_ape: Summary
    window_ape: Summary
    facade_ape: Summary
    footprint_iou: Summary
    reasons: tuple[str, ...] = ()
    steps: str | None = None
    marks: str = ""
    seeds: str | None = None
    wwr_seed_sd: Summary = Summary(None, None, 0)
    iou_seed_sd: Summary = Summary(None, None, 0)
    wwr_ape_visible: Summary = Summary(None, None, 0)
    window_ape_visible: Summary = Summary(None, None, 0)
    facade_ape_visible: Summary = Summary(None, None, 0)


def aggregate_by_family(
    rows: Sequence[BuildingErrors], *, pooled: bool = True
) -> tuple[GroupSummary, ...]:
    """One :class:`GroupSummary` per (family, method, protocol), in a stable order.

    With ``pooled``, each (method, protocol) also gets a row over all families
    (family :data:`ALL_FAMILIES`) after the per-family rows.
    """
    keys = {(r.family, r.method, r.protocol) for r in rows}
    if pooled:
        keys |= {(ALL_FAMILIES, r.method, r.protocol) for r in rows}
    groups = []
    for family, method, protocol in sorted(keys, key=_group_order):
        members = [
            r for r in rows
            if r.method == method and r.protocol == protocol
            and (family == ALL_FAMILIES or r.family == family)
        ]
        groups.append(_summarise_group(family, method, protocol, members))
    return tuple(groups)


def _summarise_group(
    family: str, method: str, protocol: str, members: Sequence[BuildingErrors]
) -> GroupSummary:
    ok = [r for r in members if r.status == "ok"]
    scenes = sorted({r.scene for r in members})
    by_scene = {s: [r for r in ok if r.scene == s] for s in scenes}

    def per_building(key: str) -> Summary:
        return summarise(seed_mean([getattr(r, key) for r in runs]) for runs in by_scene.values())

    def spread(key: str) -> Summary:
        return summarise(seed_sd([getattr(r, key) for r in runs]) for runs in by_scene.values())

    return GroupSummary(
        family=family,
        method=method,
        protocol=protocol,
        buildings=len(scenes),
        failed=sum(not runs for runs in by_scene.values()),
        wwr_ape=per_building("wwr_ape"),
        window_ape=per_building("window_ape"),
        facade_ape=per_building("facade_ape"),
        footprint_iou=per_building("footprint_iou"),
        reasons=tuple(f"{r.scene}{_seed_text(r.seed)}: {r.reason}" for r in members
                      if r.status != "ok"),
        steps=_steps_text([r.steps for r in members]),
        marks=_marks_text([r.marks for r in members]),
        seeds=_seeds_text(members),
        wwr_seed_sd=spread("wwr_ape"),
        iou_seed_sd=spread("footprint_iou"),
        wwr_ape_visible=per_building("wwr_ape_visible"),
        window_ape_visible=per_building("window_ape_visible"),
        facade_ape_visible=per_building("facade_ape_visible"),
    )


def seed_mean(values: Sequence[float | None]) -> float | None:
    """Mean of one building's values over its seeds (``None`` ones left out; all ``None``:
    ``None``)."""
    kept = [v for v in values if v is not None]
    return float(np.mean(kept)) if kept else None


def seed_sd(values: Sequence[float | None]) -> float | None:
    """Sample standard deviation (``ddof=1``) of one building's values over its seeds;
    ``None`` with fewer than two."""
    kept = [v for v in values if v is not None]
    return float(np.std(kept, ddof=1)) if len(kept) >= 2 else None


def _seed_text(seed: int | None) -> str:
    return "" if seed is None else f" (seed {seed})"


def _seeds_text(members: Sequence[BuildingErrors]) -> str | None:
    per_scene: dict[str, set[int]] = {}
    for r in members:
        if r.seed is not None:
            per_scene.setdefault(r.scene, set()).add(r.seed)
    counts = sorted({len(s) for s in per_scene.values()})
    if not counts:
        return None
    return str(counts[0]) if len(counts) == 1 else f"{counts[0]}–{counts[-1]}"


def _steps_text(steps: Sequence[int | None]) -> str | None:
    known = sorted({s for s in steps if s is not None})
    if not known:
        return None
    return str(known[0]) if len(known) == 1 else f"{known[0]}–{known[-1]}"


def _marks_text(marks: Sequence[str]) -> str:
    counts: dict[str, int] = {}
    for row in marks:
        for mark in filter(None, row.split("; ")):
            counts[mark] = counts.get(mark, 0) + 1
    return "; ".join(f"{m}: {n}" for m, n in sorted(counts.items()))


def family_rank(family: str) -> tuple[int, str]:
    """Sort key: the benchmark's families in docs/DESIGN.md order, others by name, ``all`` last."""
    if family == ALL_FAMILIES:
        return (len(BUILDING_TYPES) + 1, family)
    if family in BUILDING_TYPES:
        return (BUILDING_TYPES.index(family), family)
    return (len(BUILDING_TYPES), family)


def method_rank(method: str) -> tuple[int, str]:
    """Sort key: the built-in methods in their order (``envelope.method.BUILT_IN``), then the
    others by name."""
    return (METHOD_ORDER.index(method), method) if method in METHOD_ORDER else (99, method)


def protocol_rank(protocol: str) -> tuple[int, str]:
    """Sort key: ideal, multi, train, then others by name."""
    if protocol in PROTOCOL_ORDER:
        return (PROTOCOL_ORDER.index(protocol), protocol)
    return (99, protocol)


def _group_order(key: tuple[str, str, str]) -> tuple:
    family, method, protocol = key
    return (family_rank(family), method_rank(method), protocol_rank(protocol))
