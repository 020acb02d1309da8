"""The one table every export is made from: figures per facade and per orientation bin.

For each building: the truth's facades (method :data:`TRUTH_METHOD`) and each
result's facades, with outward azimuth and EnergyPlus bin
(:mod:`envelope.orientation`), gross / wall / window / door areas (m²) and WWR.
A facade's azimuth comes from, in this order: the truth's normal (truth rows);
the estimate's own ``normal`` (methods that locate their facades: neural3d, and the 2D
methods on views without facade ids, ``train`` and ``street``);
the truth facade with the same id (results on ideal / multi views, whose ids
are the scene's). Methods measure gross and window areas but do not separate
doors from wall: their ``wall_m2`` and ``door_m2`` stay empty.

:func:`orientation_rows` sums the facades of each bin; its WWR is the one
definition, :func:`envelope.wwr.wwr_from_areas`, of the summed areas. A bin
no facade faces has no WWR (``None``), which is not 0 (a facade without windows).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Literal

from envelope.orientation import (
    ORIENTATION_BINS,
    NorthSource,
    OrientationBin,
    azimuth_deg_from_normal,
    orientation_bin,
)
from envelope.results import FacadeEstimate, MethodResult
from envelope.truth import BuildingTruth
from envelope.wwr import wwr_from_areas

TRUTH_METHOD = "truth"  # the method name of the truth's own rows
AzimuthFrom = Literal["truth normal", "estimate normal", "truth facade", ""]


@dataclass(frozen=True)
class North:
    """A building's north: ``deg`` clockwise from true north to world +y, and where it came
    from (:data:`envelope.orientation.NorthSource`)."""

    deg: float
    source: NorthSource


def building_north(truth: BuildingTruth | None, override_deg: float | None = None) -> North:
    """``--north-deg`` when given, else the truth's stated north, else the convention (+y)."""
    if override_deg is not None:
        if not math.isfinite(override_deg):
            raise ValueError(f"--north-deg must be a finite angle in degrees, got {override_deg}")
        return North(float(override_deg) % 360.0, "user")
    if truth is not None:
        return North(truth.north_deg, truth.north_source)
    return North(0.0, "convention")


@dataclass(frozen=True)
class FacadeRow:
    """One facade of one building as one method sees it (areas in m², WWR a fraction)."""

    building: str
    method: str
    protocol: str
    facade: int
    azimuth_deg: float | None
    orientation: OrientationBin | None
    gross_m2: float | None
    wall_m2: float | None
    window_m2: float | None
    door_m2: float | None
    wwr: float | None
    azimuth_from: AzimuthFrom
    note: str = ""


@dataclass(frozen=True)
class OrientationRow:
    """The facades of one bin summed (m²); ``facades`` counted, ``missing`` of them without
    figures; ``wwr`` ``None`` when no facade with figures faces this way."""

    building: str
    method: str
    protocol: str
    orientation: OrientationBin
    facades: int
    missing: int
    gross_m2: float | None
    wall_m2: float | None
    window_m2: float | None
    door_m2: float | None
    wwr: float | None


def truth_rows(truth: BuildingTruth, north: North) -> tuple[FacadeRow, ...]:
    """The truth's facades, oriented with ``north`` (which may override the truth's)."""
    rows = []
    for f in truth.facades:
        azimuth = azimuth_deg_from_normal(f.normal, north.deg)
        rows.append(FacadeRow(
            building=truth.id, method=TRUTH_METHOD, protocol="", facade=f.id,
            azimuth_deg=azimuth, orientation=_bin(azimuth), gross_m2=f.facade_area_m2,
            wall_m2=f.wall_area_m2, window_m2=f.window_area_m2, door_m2=f.door_area_m2,
            wwr=f.wwr, azimuth_from="truth normal"))
    return tuple(rows)


def oriented_estimates(result: MethodResult, truth: BuildingTruth | None, north: North
                       ) -> tuple[tuple[FacadeEstimate, AzimuthFrom], ...]:
    """The result's facades with ``azimuth_deg`` filled, and where it came from.

    Own normal first; else, for results whose ids are the truth's, that truth
    facade's normal; else no azimuth.
    """
    true_normal = ({f.id: f.normal for f in truth.facades}
                   if truth is not None and result.facade_identity == "truth_id" else {})
    out: list[tuple[FacadeEstimate, AzimuthFrom]] = []
    for est in result.facades:
        normal, source = ((est.normal, "estimate normal") if est.normal is not None else
                          (true_normal.get(est.id), "truth facade"))
        azimuth = None if normal is None else azimuth_deg_from_normal(normal, north.deg)
        out.append((replace(est, azimuth_deg=azimuth), source if azimuth is not None else ""))
    return tuple(out)


def result_rows(result: MethodResult, truth: BuildingTruth | None, north: North
                ) -> tuple[FacadeRow, ...]:
    """The result's own facades (its ids), oriented as :func:`oriented_estimates` says."""
    rows = []
    for est, source in oriented_estimates(result, truth, north):
        missing = est.missing or est.wwr is None
        note = (est.reason or "not estimated") if missing else ""
        if not source:
            note = "; ".join(filter(None, (note, "no orientation: the result gives no facade "
                                                 "normal and the scene no building.json")))
        rows.append(FacadeRow(
            building=result.scene, method=result.method, protocol=result.protocol,
            facade=est.id, azimuth_deg=est.azimuth_deg, orientation=est.orientation,
            gross_m2=None if missing else est.facade_area_m2, wall_m2=None,
            window_m2=None if missing else est.window_area_m2, door_m2=None,
            wwr=None if missing else est.wwr, azimuth_from=source, note=note))
    return tuple(rows)


def orientation_rows(rows: Sequence[FacadeRow]) -> tuple[OrientationRow, ...]:
    """Per (building, method, protocol) in first-seen order, one row per bin N, E, S, W.

    A facade counts as missing when it lacks gross or window area; wall and door
    sums are ``None`` unless every counted facade has them.
    """
    groups: dict[tuple[str, str, str], list[FacadeRow]] = {}
    for r in rows:
        groups.setdefault((r.building, r.method, r.protocol), []).append(r)
    out = []
    for (building, method, protocol), members in groups.items():
        for b in ORIENTATION_BINS:
            facing = [r for r in members if r.orientation == b]
            known = [r for r in facing if r.gross_m2 is not None and r.window_m2 is not None]
            out.append(OrientationRow(
                building=building, method=method, protocol=protocol, orientation=b,
                facades=len(facing), missing=len(facing) - len(known),
                **_summed_areas(known)))
    return tuple(out)


def _summed_areas(known: Sequence[FacadeRow]) -> dict[str, float | None]:
    if not known:
        return {"gross_m2": None, "wall_m2": None, "window_m2": None, "door_m2": None,
                "wwr": None}
    gross = sum(r.gross_m2 for r in known)
    window = sum(r.window_m2 for r in known)
    wall = None if any(r.wall_m2 is None for r in known) else sum(r.wall_m2 for r in known)
    door = None if any(r.door_m2 is None for r in known) else sum(r.door_m2 for r in known)
    if wall is not None and door is not None:
        wwr = wwr_from_areas(window, wall, door)
    else:  # opaque = wall + door, not separated by the method
        wwr = wwr_from_areas(window, max(gross - window, 0.0), 0.0)
    return {"gross_m2": gross, "wall_m2": wall, "window_m2": window, "door_m2": door,
            "wwr": wwr}


def _bin(azimuth_deg: float | None) -> OrientationBin | None:
    return None if azimuth_deg is None else orientation_bin(azimuth_deg)
