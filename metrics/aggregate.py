"""Aggregation of per-building errors per building family: mean ± std, count and failures."""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from dataset.core.protocols import PROTOCOLS
from dataset.core.truth import BUILDING_TYPES
from metrics.errors import BuildingErrors
from metrics.methods import METHODS

ALL_FAMILIES = "all"  # the family label of the row that pools every family
METHOD_ORDER = METHODS  # the built-in methods, in the order they are declared
PROTOCOL_ORDER = PROTOCOLS


@dataclass(frozen=True)
class Summary:
    """Mean and standard deviation of ``count`` values; both ``None`` when ``count`` is 0.

    The standard deviation is the population one (``ddof=0``), so a single
    building gives 0 rather than an undefined value.
    """

    mean: float | None
    std: float | None
    count: int


def summarise(values: Iterable[float | None]) -> Summary:
    """Mean ± std of the values that are not ``None``.

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
    return Summary(float(arr.mean()), float(arr.std()), len(kept))


@dataclass(frozen=True)
class GroupSummary:
    """Errors of one (family, method, protocol) group.

    ``buildings`` counts every row of the group, ``failed`` those that gave no
    result; ``reasons`` holds ``"<scene>: <reason>"`` for each failure.
    ``steps`` is the members' step budget (``"1000"``, a range ``"500–1000"``,
    or ``None`` for methods without one); ``marks`` counts the members'
    marks (``"cut short: 1; stale: 3"``, ``""`` for none).
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
    return GroupSummary(
        family=family,
        method=method,
        protocol=protocol,
        buildings=len(members),
        failed=len(members) - len(ok),
        wwr_ape=summarise(r.wwr_ape for r in ok),
        window_ape=summarise(r.window_ape for r in ok),
        facade_ape=summarise(r.facade_ape for r in ok),
        footprint_iou=summarise(r.footprint_iou for r in ok),
        reasons=tuple(f"{r.scene}: {r.reason}" for r in members if r.status != "ok"),
        steps=_steps_text([r.steps for r in members]),
        marks=_marks_text([r.marks for r in members]),
    )


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
    """Sort key: the benchmark's families in DESIGN.md order, others by name, ``all`` last."""
    if family == ALL_FAMILIES:
        return (len(BUILDING_TYPES) + 1, family)
    if family in BUILDING_TYPES:
        return (BUILDING_TYPES.index(family), family)
    return (len(BUILDING_TYPES), family)


def method_rank(method: str) -> tuple[int, str]:
    """Sort key: the built-in methods in their order (``metrics.methods.METHODS``), then the
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
