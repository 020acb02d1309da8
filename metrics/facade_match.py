"""Match a method's own facades to the truth's facades, so per-facade errors can be taken.

Methods that find facades without ground truth (grouping a mesh by
normal direction) number them 1..K in their own order. Evaluation pairs them
with the truth by where they are, from each estimate's ``normal`` and
``centre_m`` (world frame, :class:`dataset.core.results.FacadeEstimate`) and the
truth's ``building.json``:

1. the truth's walls are the outlines in ``BuildingTruth.facade_outlines_m`` (one
   polygon per wall, one per facet of a curved wall); an estimate may go to a
   wall whose normal agrees within ``MAX_NORMAL_ANGLE_DEG`` (45 degrees) with its own;
2. of those, it goes to the facade of the wall nearest to its centre (3D
   distance to the polygon); a truth facade without outlines (imported
   buildings) counts as one wall with the facade's normal at unknown distance,
   so it ranks after every wall with an outline, by normal angle;
3. several estimates on one truth facade (segments of a curved wall, a wall the
   method split) are merged: window and facade areas add up, WWR is recomputed
   by :class:`dataset.core.wwr.ClassAreas`, widths add and the largest
   height stays;
4. a truth facade no estimate reaches is reported missing; an estimate whose
   normal agrees with no truth facade is left out with a reason, and so is one farther
   from its facade than ``max_distance_m`` where a limit is given (a truth that counts
   only some walls, :mod:`metrics.covered_facades`).

Only the method's figures are used; the truth decides which facade they belong to.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from shapely.geometry import Point, Polygon

from dataset.core.results import FacadeEstimate
from dataset.core.truth import BuildingTruth
from dataset.core.wwr import ClassAreas

MAX_NORMAL_ANGLE_DEG = 45.0  # an estimate may face a truth facade only if normals agree this well


@dataclass(frozen=True)
class FacadeMatch:
    """Estimates renumbered to the truth's facade ids.

    ``facades``: one :class:`FacadeEstimate` per truth facade, in the truth's
    order, with the truth's id; ``missing`` with a reason where no estimate
    reached it. ``left_out``: (estimate id, reason) of estimates that went nowhere.
    """

    facades: tuple[FacadeEstimate, ...]
    left_out: tuple[tuple[int, str], ...]


def has_facade_geometry(estimates: Sequence[FacadeEstimate]) -> bool:
    """Whether every estimate carries ``normal`` and ``centre_m`` (and there is one at all)."""
    return len(estimates) > 0 and all(
        e.normal is not None and e.centre_m is not None for e in estimates)


def match_facades(estimates: Sequence[FacadeEstimate], truth: BuildingTruth, *,
                  max_distance_m: float | None = None) -> FacadeMatch:
    """Give ``estimates`` the truth's facade ids (see the module docstring).

    ``max_distance_m``: an estimate whose centre lies farther than this from its facade's
    nearest wall outline is left out (a wall the truth does not count;
    :mod:`metrics.covered_facades`); ``None``: no limit. A facade without outlines cannot
    be checked: estimates on it are kept.

    Raises
    ------
    ValueError
        If an estimate lacks ``normal`` or ``centre_m``, or its normal has no length.
    """
    owners: dict[int, list[FacadeEstimate]] = {}
    left_out: list[tuple[int, str]] = []
    outlines = truth.facade_outlines_m
    for est in estimates:
        if est.normal is None or est.centre_m is None:
            raise ValueError(f"estimated facade {est.id} has no normal or centre_m; only "
                             "results that locate their facades can be matched to the truth")
        located = facade_owner(est, truth, outlines)
        owner = None if located is None else located[0]
        if owner is None:
            left_out.append((est.id, f"estimated facade {est.id} faces no truth facade "
                                     f"(normal within {MAX_NORMAL_ANGLE_DEG:g} degrees)"))
        elif max_distance_m is not None and np.isfinite(located[1]) and located[1] > max_distance_m:
            left_out.append((est.id, f"estimated facade {est.id} lies {located[1]:.1f} m from "
                                     f"truth facade {owner}, farther than {max_distance_m:g} m: "
                                     "a wall the truth does not count"))
        else:
            owners.setdefault(owner, []).append(est)
    facades = tuple(
        _merge(owners[t.id], t.id) if t.id in owners else
        FacadeEstimate(id=t.id, wwr=None, missing=True,
                       reason="no estimated facade lies on this facade")
        for t in truth.facades
    )
    return FacadeMatch(facades, tuple(left_out))


def distance_to_outline_m(point_m: Sequence[float], outline_m: Sequence[Sequence[float]]) -> float:
    """Distance in m from a world point to a planar polygon given by its (n, 3) world corners."""
    corners = np.asarray(outline_m, dtype=np.float64)
    if corners.ndim != 2 or corners.shape[1] != 3 or len(corners) < 3:
        raise ValueError(f"an outline needs (n >= 3, 3) corners, got shape {corners.shape}")
    origin = corners.mean(axis=0)
    normal = _newell_normal(corners)
    u = corners[int(np.argmax(np.linalg.norm(corners - origin, axis=1)))] - origin
    u = u - (u @ normal) * normal
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    rel = corners - origin
    p = np.asarray(point_m, dtype=np.float64) - origin
    in_plane_m = Polygon(np.stack([rel @ u, rel @ v], axis=1)).distance(Point(p @ u, p @ v))
    return float(np.hypot(p @ normal, in_plane_m))


def facade_owner(est: FacadeEstimate, truth: BuildingTruth,
                 outlines: dict | None = None) -> tuple[int, float] | None:
    """The truth facade ``est`` goes to (rules 1-2 of the module docstring) and the distance
    in m from its centre to that facade's nearest wall outline (``inf`` for a facade without
    outlines); ``None`` where no truth facade's normal agrees with its own.

    Raises
    ------
    ValueError
        If the estimate's normal has no length.
    """
    outlines = truth.facade_outlines_m if outlines is None else outlines
    n = np.asarray(est.normal, dtype=np.float64)
    if not np.linalg.norm(n) > 0:
        raise ValueError(f"estimated facade {est.id} has a zero normal")
    n = n / np.linalg.norm(n)
    min_cos = np.cos(np.radians(MAX_NORMAL_ANGLE_DEG))
    best: tuple[float, float, int] | None = None
    for t in truth.facades:
        # each wall (facet) of a facade with outlines faces its own way: a curved
        # facade's segments agree with their facets, not with the mean normal
        walls = [np.asarray(w, dtype=np.float64) for w in outlines.get(t.id, ())]
        candidates = [(distance_to_outline_m(est.centre_m, w), float(n @ _newell_normal(w)))
                      for w in walls]
        if not walls:
            tn = np.asarray(t.normal, dtype=np.float64)
            candidates = [(np.inf, float(n @ tn) / max(float(np.linalg.norm(tn)), 1e-12))]
        for distance, cos in candidates:
            if cos > min_cos and (best is None or (distance, -cos, t.id) < best):
                best = (distance, -cos, t.id)
    return None if best is None else (best[2], best[0])


def _merge(parts: list[FacadeEstimate], facade_id: int) -> FacadeEstimate:
    if len(parts) == 1:
        return replace(parts[0], id=facade_id)
    ids = ", ".join(str(p.id) for p in parts)
    areas = [(p.window_area_m2, p.facade_area_m2) for p in parts]
    if any(a is None for pair in areas for a in pair):
        return FacadeEstimate(id=facade_id, wwr=None, missing=True,
                              reason=f"estimated facades {ids} lie on this facade but not all "
                                     "have window and facade areas to merge")
    window = sum(w for w, _ in areas)
    gross = sum(g for _, g in areas)
    weight = np.array([g for _, g in areas]) + 1e-12  # areas may all be 0
    normal = np.average([p.normal for p in parts], axis=0, weights=weight)
    normal /= max(float(np.linalg.norm(normal)), 1e-12)
    widths = [p.width_m for p in parts]
    heights = [p.height_m for p in parts]
    return FacadeEstimate(
        id=facade_id,
        wwr=ClassAreas(window, gross - window, 0.0).wwr,
        window_area_m2=window,
        facade_area_m2=gross,
        width_m=None if None in widths else sum(widths),
        height_m=None if None in heights else max(heights),
        views_used=sum(p.views_used for p in parts),
        reason=f"merged from estimated facades {ids}",
        normal=tuple(float(c) for c in normal),
        centre_m=tuple(float(c) for c in np.average([p.centre_m for p in parts], axis=0,
                                                     weights=weight)),
    )


def _newell_normal(corners: np.ndarray) -> np.ndarray:
    nxt = np.roll(corners, -1, axis=0)
    n = np.array([
        np.sum((corners[:, 1] - nxt[:, 1]) * (corners[:, 2] + nxt[:, 2])),
        np.sum((corners[:, 2] - nxt[:, 2]) * (corners[:, 0] + nxt[:, 0])),
        np.sum((corners[:, 0] - nxt[:, 0]) * (corners[:, 1] + nxt[:, 1])),
    ])
    length = float(np.linalg.norm(n))
    if length == 0:
        raise ValueError("an outline has no area (its corners are on one line)")
    return n / length
