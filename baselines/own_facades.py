"""2D-SS and 2D-S on posed views without facade ids: the methods find the facades themselves.

On a street (or the orbit ``train`` views) nobody says which facade a photo shows, and a
photo may show several. Both methods then:

1. fit vertical planes to each view's depth (:mod:`baselines.view_planes`); a view with
   none is skipped with the reason;
2. merge the planes of all views into facades (:mod:`baselines.plane_merge`): the
   method's own facades, ids 1..K in order of their outward normal's azimuth
   (counter-clockwise from +x), each with its ``normal`` and ``centre_m`` so that
   evaluation pairs them with the truth's walls (:mod:`metrics.score.facade_match`).

**2D-SS** measures each facade on its plane by cell voting (:mod:`baselines.facade_cells`):
window, wall and door areas without counting what several views see twice; ``centre_m``
is the centre of its measured cells. A facade under ``min_facade_area_m2`` is dropped (a
chimney, a parapet, a sliver of a wall seen edge-on). The building's areas are the sums
over its facades and its WWR their ratio (:class:`envelope.wwr.ClassAreas`).

**2D-S** groups views by their dominant plane (the one with most pixels): views whose
dominant planes merged into one facade form its group. Per view, the paper's pixel ratio on
that facade's pixels (wall, window and door pixels whose surface lies on the facade's plane,
``front_m`` in front to ``back_m`` behind, within its extent widened by ``pad_m``), with the
area scale (z/f)² at their median depth as 2D-S does (:mod:`baselines.wwr2ds`); per facade
the mean (or median) over its group; the building WWR is the unweighted mean over facades.
A facade whose group measured less than ``min_facade_area_m2`` is dropped as in 2D-SS.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from baselines.aggregate import Combine, building_result, combine_values
from baselines.facade_cells import CellAreas, CellConfig, measure_facades
from baselines.plane_merge import FacadePlane, MergeConfig, merge_view_planes
from baselines.posed_views import PosedView, PosedViews, load_posed_views
from baselines.view_planes import PlaneFitConfig, ViewPlane, find_view_planes
from envelope.classes import SemanticClass
from envelope.method_input import MethodInput
from envelope.results import FacadeEstimate, MethodResult, code_version
from envelope.scene_record import scene_name
from envelope.wwr import ClassAreas, wwr_from_areas


@dataclass(frozen=True)
class OwnFacadesConfig:
    """How the 2D methods find and measure facades on views without facade ids (module
    docstring); chosen on the tiny preset (docs/baselines.md)."""

    fit: PlaneFitConfig = field(default_factory=PlaneFitConfig)
    merge: MergeConfig = field(default_factory=MergeConfig)
    cells: CellConfig = field(default_factory=CellConfig)
    min_facade_area_m2: float = 4.0

    def __post_init__(self) -> None:
        if not self.min_facade_area_m2 >= 0:
            raise ValueError("min_facade_area_m2 must be >= 0")


@dataclass(frozen=True)
class FoundFacades:
    """The views, each usable view's planes (largest first) and the merged facades."""

    loaded: PosedViews
    planes: dict[int, list[ViewPlane]]
    facades: list[FacadePlane]

    def facade_of(self, plane: ViewPlane) -> int:
        """Index in ``facades`` of the facade a view plane was merged into."""
        return next(i for i, f in enumerate(self.facades) if any(m is plane for m in f.members))


def find_own_facades(scene: MethodInput, protocol: str, config: OwnFacadesConfig,
                     seed: int) -> FoundFacades:
    """Steps 1-2 of the module docstring on the views of ``protocol``, facades in id order."""
    loaded = load_posed_views(scene, protocol)
    planes: dict[int, list[ViewPlane]] = {}
    for view in loaded.views:
        found = find_view_planes(view, config.fit, np.random.default_rng((seed, view.index)))
        if found:
            planes[view.index] = found
        else:
            loaded.skip(view.name, f"no vertical facade plane of at least "
                                   f"{config.fit.min_points} pixels")
    loaded.views = [v for v in loaded.views if v.index in planes]
    facades = merge_view_planes([p for ps in planes.values() for p in ps], config.merge)
    return FoundFacades(loaded, planes, sorted(facades, key=_azimuth_order))


def run_2dss_own(scene: MethodInput, protocol: str, config: OwnFacadesConfig, *, seed: int,
                 method: str, method_config: dict[str, Any]) -> MethodResult:
    """2D-SS on views without facade ids (module docstring).

    Raises
    ------
    ValueError
        If the scene has no such views or no facade is found.
    """
    start = time.perf_counter()
    found = find_own_facades(scene, protocol, config, seed)
    measured: list[tuple[FacadePlane, CellAreas]] = [
        (facade, cells) for facade, cells in zip(
            found.facades, measure_facades(found.facades, found.loaded.views, config.cells))
        if cells is not None and cells.areas.gross_m2 >= config.min_facade_area_m2]
    warnings = list(found.loaded.warnings)
    dropped = len(found.facades) - len(measured)
    if dropped:
        warnings.append(f"{dropped} planes found measured under {config.min_facade_area_m2:g} "
                        "m² of facade and were dropped")
    facades = [FacadeEstimate(
        id=i, wwr=c.areas.wwr, window_area_m2=c.areas.window_m2, facade_area_m2=c.areas.gross_m2,
        width_m=c.width_m, height_m=c.height_m, views_used=c.views,
        normal=_vector(f.normal), centre_m=_vector(c.centre_m),
    ) for i, (f, c) in enumerate(measured, start=1)]
    name = scene_name(scene)
    if not facades:
        raise ValueError(f"{name} ({method}, {protocol}): nothing left to measure: no facade "
                         f"found; {'; '.join(warnings) or 'no usable view'}")
    total = ClassAreas(sum(c.areas.window_m2 for _, c in measured),
                       sum(c.areas.wall_m2 for _, c in measured),
                       sum(c.areas.door_m2 for _, c in measured))
    return MethodResult(
        scene=name, method=method, protocol=protocol, wwr=total.wwr,
        window_area_m2=total.window_m2, facade_area_m2=total.gross_m2, facades=tuple(facades),
        config=method_config, code_version=code_version(),
        wall_time_s=time.perf_counter() - start, warnings=tuple(warnings),
        facade_identity="geometry",
    )


@dataclass(frozen=True)
class ViewRatio:
    """2D-S on one view's dominant facade: pixel counts and the (z/f)² pixel area (m²)."""

    window_px: int
    door_px: int
    facade_px: int
    pixel_area_m2: float

    @property
    def wwr(self) -> float | None:
        return wwr_from_areas(self.window_px, self.facade_px - self.window_px - self.door_px,
                              self.door_px)


def facade_pixel_ratio(view: PosedView, facade: FacadePlane, cells: CellConfig) -> ViewRatio:
    """The pixel counts of ``facade`` in ``view``: wall, window and door pixels whose surface
    lies on its plane (``cells.front_m`` in front to ``cells.back_m`` behind) within its
    extent widened by ``cells.pad_m``."""
    points = view.world_points_m()
    signed_m = points @ facade.normal - facade.offset_m  # > 0: in front of the plane
    s = points @ facade.along
    lo, hi = facade.s_range_m
    mask = (view.facade_pixels() & (signed_m <= cells.front_m) & (signed_m >= -cells.back_m)
            & (s >= lo - cells.pad_m) & (s <= hi + cells.pad_m))
    depth = view.depth_z_m[mask]
    k = view.intrinsics
    pixel_area = float(np.median(depth)) ** 2 / (k.fx * k.fy) if len(depth) else 0.0
    return ViewRatio(int(np.count_nonzero(mask & (view.labels == SemanticClass.WINDOW))),
                     int(np.count_nonzero(mask & (view.labels == SemanticClass.DOOR))),
                     int(np.count_nonzero(mask)), pixel_area)


def run_2ds_own(scene: MethodInput, protocol: str, config: OwnFacadesConfig, *,
                combine: Combine, method: str, method_config: dict[str, Any]) -> MethodResult:
    """2D-S on views without facade ids (module docstring).

    Raises
    ------
    ValueError
        If the scene has no such views or no facade is found.
    """
    start = time.perf_counter()
    found = find_own_facades(scene, protocol, config, seed=0)
    groups: dict[int, list[ViewRatio]] = {}
    for view in found.loaded.views:
        index = found.facade_of(found.planes[view.index][0])
        ratio = facade_pixel_ratio(view, found.facades[index], config.cells)
        if ratio.facade_px:
            groups.setdefault(index, []).append(ratio)
    warnings = list(found.loaded.warnings)
    facades = []
    for index in sorted(groups):
        ratios, plane = groups[index], found.facades[index]
        area = combine_values([r.facade_px * r.pixel_area_m2 for r in ratios], combine)
        if area < config.min_facade_area_m2:
            warnings.append(f"a facade measured {area:.1f} m², under "
                            f"{config.min_facade_area_m2:g} m², was dropped")
            continue
        facades.append(FacadeEstimate(
            id=len(facades) + 1, wwr=combine_values([r.wwr for r in ratios], combine),
            window_area_m2=combine_values([r.window_px * r.pixel_area_m2 for r in ratios],
                                          combine),
            facade_area_m2=area, width_m=float(np.ptp(plane.s_range_m)),
            height_m=float(np.ptp(plane.z_range_m)), views_used=len(ratios),
            normal=_vector(plane.normal), centre_m=_vector(plane.centre_m)))
    result = building_result(
        scene=scene_name(scene), method=method, protocol=protocol, facades=facades,
        weighting="equal", config=method_config, wall_time_s=0.0, warnings=warnings)
    return replace(result, facade_identity="geometry", wall_time_s=time.perf_counter() - start)


def _azimuth_order(facade: FacadePlane) -> tuple[float, float]:
    azimuth = float(np.degrees(np.arctan2(facade.normal[1], facade.normal[0]))) % 360.0
    return round(azimuth, 3), float(facade.centre_m @ facade.along)


def _vector(v: np.ndarray) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))
