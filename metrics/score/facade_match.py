"""Match a method's own facades to the truth's walls: the one rule every method is scored by.

Methods that find facades without the truth (grouping a mesh by normal direction, fitting
planes to depth) number them 1..K in their own order. Evaluation pairs them with the truth
by where they are, from each estimate's ``normal`` and ``centre_m`` (world frame,
:class:`envelope.results.FacadeEstimate`) and the truth's ``building.json``. The truth's
walls are its facades' outlines (``BuildingTruth.facade_outlines_m``: one polygon per wall,
one per facet of a curved wall) and, where it counts only some walls (a CityGML model's
covered facades), the outlines of the walls it lists apart
(``BuildingTruth.uncovered_outlines_m``: backyard and party walls).

1. An estimate may go to a wall whose normal agrees within ``MAX_NORMAL_ANGLE_DEG`` (45
   degrees) with its own; of those, to the wall nearest its centre (3D distance to the
   polygon). A truth facade without outlines (imported meshes) counts as one wall with the
   facade's normal at unknown distance: it ranks after every wall with an outline, by
   normal angle, and the distance limit cannot be checked on it.
2. An estimate whose nearest such wall lies farther than ``ON_WALL_MAX_DISTANCE_M`` (1 m),
   or that faces no wall, is a **false positive**: a wall the truth does not have.
3. An estimate on an uncovered wall is **out of scope**: it leaves the building's figures
   with that wall (:mod:`metrics.score.facade_scoring`).
4. Several estimates on one truth facade (segments of a curved wall, a wall the method
   split) are merged: window and facade areas add up, WWR is recomputed by
   :class:`envelope.wwr.ClassAreas`, widths add and the largest height stays. So a
   truth facade has at most one estimate, and each estimate one truth facade.
5. A truth facade no estimate reaches is **missed**.

Only the method's figures are used; the truth decides which facade they belong to. The
limit of rule 2 was chosen on the paper preset (the set settings are chosen on,
docs/decisions.md): neural3d's facade centres there lie 0.00-0.10 m from their facade's
wall outline (6 runs on 4 buildings, 28 facades); 1 m leaves ten times that and is less
than the depth of a bay or a balcony.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from shapely.geometry import Point, Polygon

from envelope.polygons import newell_normal
from envelope.results import FacadeEstimate
from envelope.truth import BuildingTruth
from envelope.wwr import ClassAreas

MAX_NORMAL_ANGLE_DEG = 45.0  # an estimate may face a truth wall only if normals agree this well
ON_WALL_MAX_DISTANCE_M = 1.0  # an estimate's centre within this of its wall, else a false positive
UNCOVERED = -1  # owner of an estimate on a wall the truth lists apart


@dataclass(frozen=True)
class Unmatched:
    """An estimate that went to no covered truth facade, and why."""

    estimate: FacadeEstimate
    reason: str


@dataclass(frozen=True)
class FacadeMatch:
    """Estimates renumbered to the truth's facade ids under the one rule.

    ``facades``: one :class:`FacadeEstimate` per truth facade, in the truth's order, with the
    truth's id; ``missing`` with a reason where no estimate reached it. ``out_of_scope``:
    estimates on walls the truth does not count. ``false_positives``: estimates on no wall
    of the truth.
    """

    facades: tuple[FacadeEstimate, ...]
    out_of_scope: tuple[Unmatched, ...] = ()
    false_positives: tuple[Unmatched, ...] = ()


def has_facade_geometry(estimates: Sequence[FacadeEstimate]) -> bool:
    """Whether every estimate carries ``normal`` and ``centre_m`` (and there is one at all)."""
    return len(estimates) > 0 and all(
        e.normal is not None and e.centre_m is not None for e in estimates)


def match_facades(estimates: Sequence[FacadeEstimate], truth: BuildingTruth, *,
                  max_distance_m: float = ON_WALL_MAX_DISTANCE_M) -> FacadeMatch:
    """Give ``estimates`` the truth's facade ids (rules 1-5 of the module docstring).

    Raises
    ------
    ValueError
        If an estimate lacks ``normal`` or ``centre_m``, or its normal has no length, or the
        truth's uncovered walls have no outlines (an old scene).
    """
    owners: dict[int, list[FacadeEstimate]] = {}
    out_of_scope: list[Unmatched] = []
    false_positives: list[Unmatched] = []
    outlines = truth.facade_outlines_m
    uncovered = truth.uncovered_outlines_m
    for est in estimates:
        if est.normal is None or est.centre_m is None:
            raise ValueError(f"estimated facade {est.id} has no normal or centre_m; only "
                             "results that locate their facades can be matched to the truth")
        located = facade_owner(est, truth, outlines, uncovered)
        if located is None:
            false_positives.append(Unmatched(est, (
                f"estimated facade {est.id} faces no wall of the truth (normal within "
                f"{MAX_NORMAL_ANGLE_DEG:g} degrees): a false positive")))
            continue
        owner, distance_m = located
        if np.isfinite(distance_m) and distance_m > max_distance_m:
            false_positives.append(Unmatched(est, (
                f"estimated facade {est.id} lies {distance_m:.1f} m from the nearest wall of "
                f"the truth facing its way, farther than {max_distance_m:g} m: a false "
                "positive")))
        elif owner == UNCOVERED:
            out_of_scope.append(Unmatched(est, (
                f"estimated facade {est.id} lies on a wall the truth does not count")))
        else:
            owners.setdefault(owner, []).append(est)
    facades = tuple(
        _merge(owners[t.id], t.id) if t.id in owners else
        FacadeEstimate(id=t.id, wwr=None, missing=True,
                       reason="no estimated facade lies on this facade")
        for t in truth.facades
    )
    return FacadeMatch(facades, tuple(out_of_scope), tuple(false_positives))


def distance_to_outline_m(point_m: Sequence[float], outline_m: Sequence[Sequence[float]]) -> float:
    """Distance in m from a world point to a planar polygon given by its (n, 3) world corners."""
    corners = np.asarray(outline_m, dtype=np.float64)
    if corners.ndim != 2 or corners.shape[1] != 3 or len(corners) < 3:
        raise ValueError(f"an outline needs (n >= 3, 3) corners, got shape {corners.shape}")
    origin = corners.mean(axis=0)
    normal = newell_normal(corners)
    u = corners[int(np.argmax(np.linalg.norm(corners - origin, axis=1)))] - origin
    u = u - (u @ normal) * normal
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    rel = corners - origin
    p = np.asarray(point_m, dtype=np.float64) - origin
    in_plane_m = Polygon(np.stack([rel @ u, rel @ v], axis=1)).distance(Point(p @ u, p @ v))
    return float(np.hypot(p @ normal, in_plane_m))


def facade_owner(est: FacadeEstimate, truth: BuildingTruth, outlines: dict | None = None,
                 uncovered: Sequence | None = None) -> tuple[int, float] | None:
    """The truth facade ``est`` goes to (:data:`UNCOVERED` for a wall the truth lists apart;
    rule 1 of the module docstring) and the distance in m from its centre to that wall
    (``inf`` for a facade without outlines); ``None`` where no wall's normal agrees with its
    own.

    Raises
    ------
    ValueError
        If the estimate's normal has no length.
    """
    outlines = truth.facade_outlines_m if outlines is None else outlines
    uncovered = truth.uncovered_outlines_m if uncovered is None else uncovered
    n = np.asarray(est.normal, dtype=np.float64)
    if not np.linalg.norm(n) > 0:
        raise ValueError(f"estimated facade {est.id} has a zero normal")
    n = n / np.linalg.norm(n)
    min_cos = np.cos(np.radians(MAX_NORMAL_ANGLE_DEG))
    best: tuple[float, float, bool, int] | None = None  # a tie goes to a covered facade
    walls_by_owner = [(t.id, outlines.get(t.id, ()), t.normal) for t in truth.facades]
    walls_by_owner += [(UNCOVERED, (w,), None) for w in uncovered]
    for owner, walls, facade_normal in walls_by_owner:
        # each wall (facet) of a facade with outlines faces its own way: a curved
        # facade's segments agree with their facets, not with the mean normal
        walls = [np.asarray(w, dtype=np.float64) for w in walls]
        candidates = [(distance_to_outline_m(est.centre_m, w), float(n @ newell_normal(w)))
                      for w in walls]
        if not walls:
            tn = np.asarray(facade_normal, dtype=np.float64)
            candidates = [(np.inf, float(n @ tn) / max(float(np.linalg.norm(tn)), 1e-12))]
        for distance, cos in candidates:
            key = (distance, -cos, owner == UNCOVERED, owner)
            if cos > min_cos and (best is None or key < best):
                best = key
    return None if best is None else (best[3], best[0])


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
