"""Scale, north and place from a city model (``--city-model``): the photos' levelled sparse
points fitted to the model's surfaces by a similarity about the vertical (scale, heading,
3D shift), with no initial guess (docs/importing.md, section 9).

1. *Search* (:mod:`dataset.importers.photos.city_search`): headings and scales on grids,
   the horizontal shift by correlating the points' ground projection with the model's wall
   lines; the best :attr:`~dataset.importers.photos.city_search.SearchConfig.candidates`
   distinct peaks are kept, and the best shifts at the best peak's scale with its heading
   turned a quarter, a half and three quarters.
2. *Refine* each (:mod:`dataset.importers.photos.city_icp`): trimmed point-to-plane ICP with
   scale, down to the inlier distance
   :data:`~dataset.importers.photos.city_icp.TRIMS_M` ``[-1]``; the fit that brings the most
   points within it of a surface wins.
3. *Refuse* (one line, nothing written) a fit that is bad or ambiguous
   (:class:`CityFitConfig`, :func:`check_fit`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dataset.importers.photos.city_icp import (
    TRIMS_M,
    PlacedSimilarity,
    Residuals,
    refine,
    surface_samples,
)
from dataset.importers.photos.city_search import (
    SearchConfig,
    coarse_candidates,
    distinct,
    scale_guess,
)
from dataset.importers.photos.city_target import CityTarget

FALLBACK = "give --known-distance or --known-height instead"
POINT_SEED = 0


@dataclass(frozen=True)
class CityFitConfig:
    """The fit's settings and its refusal rules.

    ``max_points``: the sparse points used at most (drawn with a fixed seed);
    ``min_inliers`` and ``min_inlier_share``: the least count and share of them within the
    inlier distance of a model surface after the fit (fewer: a bad fit, refused);
    ``min_on_building_share``: the least share of those inliers on the named building's
    own surfaces (the photos show it; fewer: they were fitted to its neighbours alone, a bad
    fit, refused);
    ``ambiguity_ratio``: a second, distinct fit (another heading, scale or place) bringing
    at least this share of the best one's points within the best one's own yardstick
    (:attr:`CityFit.judge_m`: ``judge_factor`` times its median inlier residual, at least
    ``min_judge_m`` metres and at most the inlier distance) makes the fit ambiguous
    (refused).
    docs/decisions.md (2026-11-29, "Scale from a city model") says where the numbers come
    from."""

    search: SearchConfig = SearchConfig()
    max_points: int = 20000
    min_inliers: int = 200
    min_inlier_share: float = 0.2
    min_on_building_share: float = 0.25
    ambiguity_ratio: float = 0.8
    judge_factor: float = 3.0
    min_judge_m: float = 0.05

    def __post_init__(self) -> None:
        if not (self.max_points >= self.min_inliers >= 10 and 0 < self.min_inlier_share < 1
                and 0 < self.ambiguity_ratio < 1):
            raise ValueError(f"city fit config out of range: {self}")


@dataclass(frozen=True)
class Solution:
    """One refined candidate: its similarity and residuals (over the points used)."""

    similarity: PlacedSimilarity
    residuals: Residuals

    @property
    def inliers(self) -> int:
        """Points within the inlier distance of a model surface that faces their camera."""
        return int(self.residuals.inlier.sum())

    def within(self, distance_m: float) -> int:
        """Inliers within ``distance_m`` of their surface."""
        res = self.residuals
        return int((res.inlier & (res.distance_m <= distance_m)).sum())


@dataclass(frozen=True)
class CityFit:
    """The best fit, the other fits distinct from it and from each other (most points
    within ``judge_m`` first; none where every start came to the best one), the points
    used, the yardstick ``judge_m`` they are compared by (the best fit's median inlier
    residual times ``judge_factor``, within ``min_judge_m`` and the inlier distance: a fit
    as tight as the best one explains the points as well), and the share of the best fit's
    inliers on the building's own surfaces."""

    best: Solution
    others: tuple[Solution, ...]
    points_used: int
    judge_m: float
    on_building_share: float

    @property
    def runner_up(self) -> Solution | None:
        """The strongest other fit, or ``None``."""
        return self.others[0] if self.others else None

    @property
    def runner_up_ratio(self) -> float:
        """The runner-up's points within ``judge_m`` over the best one's (0 without a
        runner-up)."""
        if self.runner_up is None:
            return 0.0
        return self.runner_up.within(self.judge_m) / max(self.best.within(self.judge_m), 1)

    def record(self, target: CityTarget, config: CityFitConfig) -> dict:
        """The ``city_model`` entry of the scene's ``photos`` record."""
        res = self.best.residuals
        inlier = res.distance_m[res.inlier]
        out = {**target.record(),
               "points_used": self.points_used, "inliers": self.best.inliers,
               "inlier_share": round(self.best.inliers / self.points_used, 4),
               "inlier_distance_m": res.trim_m,
               "on_building_share": round(self.on_building_share, 4),
               "residual_median_m": round(float(np.median(inlier)), 4),
               "residual_rms_m": round(float(np.sqrt(np.mean(inlier ** 2))), 4),
               "scale_factor": self.best.similarity.scale,
               "heading_deg": round(float(np.degrees(self.best.similarity.heading_rad)), 4),
               "judge_m": round(self.judge_m, 4),
               "runner_up_ratio": round(self.runner_up_ratio, 4),
               "rules": {"min_inliers": config.min_inliers,
                         "min_inlier_share": config.min_inlier_share,
                         "min_on_building_share": config.min_on_building_share,
                         "ambiguity_ratio": config.ambiguity_ratio}}
        out["best_within_judge"] = self.best.within(self.judge_m)
        out["alternatives"] = [{"heading_deg": round(float(np.degrees(o.similarity.heading_rad)),
                                                     2),
                                "scale_factor": o.similarity.scale, "inliers": o.inliers,
                                "within_judge": o.within(self.judge_m)} for o in self.others]
        return out


def fit_city_model(points: np.ndarray, cameras: np.ndarray, ground_z: float, top_z: float,
                   target: CityTarget, config: CityFitConfig = CityFitConfig()) -> CityFit:
    """The similarity taking (N, 3) levelled sparse points (z up, any scale; their ground
    and top at heights ``ground_z`` and ``top_z``), seen from (K, 3) levelled camera
    centres, onto ``target``'s surfaces (module docstring).

    Raises
    ------
    ValueError
        Too few points, a bad fit or an ambiguous one (:func:`check_fit`), with the rule.
    """
    points = np.asarray(points, dtype=np.float64)
    if len(points) < config.min_inliers:
        raise ValueError(f"--city-model: structure from motion gave {len(points)} sparse "
                         f"points; the fit needs at least {config.min_inliers} on the model's "
                         f"surfaces: {FALLBACK}")
    if len(points) > config.max_points:
        rng = np.random.default_rng(POINT_SEED)
        points = points[np.sort(rng.choice(len(points), config.max_points, replace=False))]
    samples = surface_samples(target.triangles_m, target.building_triangles)
    ground = np.array([*np.median(points[:, :2], axis=0), ground_z])
    middle = np.median(points, axis=0)
    coarse = [c.similarity for c in coarse_candidates(
        points, ground_z, top_z, samples, target.building_height_m, config.search)]
    guess = scale_guess(ground_z, top_z, target.building_height_m)
    low, high = (guess * np.exp(sign * config.search.scale_step) * config.search.scale_range
                 ** sign for sign in (-1, 1))
    solutions = []
    for start in coarse:
        similarity, res = refine(points, cameras, ground, samples, start)
        if low <= similarity.scale <= high:  # else it ran off the scales searched
            solutions.append(Solution(similarity, res))
    if not solutions:
        raise ValueError(f"--city-model: every fit ran off the scales searched ({low:.3g} to "
                         f"{high:.3g}, from the building's height): the photos may not show "
                         f"its foot and top, or show another place: {FALLBACK}")
    solutions.sort(key=lambda s: -s.inliers)
    best = solutions[0]
    others: list[Solution] = []
    for s in solutions[1:]:
        if all(distinct(k.similarity, s.similarity, middle, config.search)
               for k in [best, *others]):
            others.append(s)
    residual = float(np.median(best.residuals.distance_m[best.residuals.inlier])) \
        if best.inliers else TRIMS_M[-1]
    judge = float(np.clip(config.judge_factor * residual, config.min_judge_m, TRIMS_M[-1]))
    others.sort(key=lambda s: -s.within(judge))
    res = best.residuals
    on_building = float(samples.own[res.nearest[res.inlier]].mean()) if best.inliers else 0.0
    fit = CityFit(best, tuple(others), len(points), judge, on_building)
    check_fit(fit, target, config)
    return fit


def check_fit(fit: CityFit, target: CityTarget, config: CityFitConfig) -> None:
    """Refuse a bad fit (fewer than ``min_inliers`` or ``min_inlier_share`` of the points
    near a surface, or under ``min_on_building_share`` of those on the building itself) or
    an ambiguous one (a distinct runner-up with ``ambiguity_ratio`` of
    the best one's points within ``fit.judge_m``, or more).

    Raises
    ------
    ValueError
        One line: what was found, the rule, and what to do.
    """
    share = fit.best.inliers / fit.points_used
    trim = TRIMS_M[-1]
    where = f"building {target.building} and its {len(target.neighbours)} neighbours"
    if fit.best.inliers < config.min_inliers or share < config.min_inlier_share:
        raise ValueError(
            f"--city-model: after the best fit only {fit.best.inliers} of {fit.points_used} "
            f"sparse points ({share:.0%}) lie within {trim:g} m of a surface of {where}; at "
            f"least {config.min_inliers} and {config.min_inlier_share:.0%} must: the photos "
            f"show another place or another building (check --city-building), or the model "
            f"too little of what they show: {FALLBACK}")
    if fit.on_building_share < config.min_on_building_share:
        raise ValueError(
            f"--city-model: the best fit puts {fit.on_building_share:.0%} of the "
            f"{fit.best.inliers} points near a surface on building {target.building} itself, "
            f"the rest on its neighbours; at least {config.min_on_building_share:.0%} must lie "
            f"on the building the photos show: check --city-building, or {FALLBACK}")
    if fit.runner_up is not None and fit.runner_up_ratio >= config.ambiguity_ratio:
        a, b = fit.best.similarity, fit.runner_up.similarity
        raise ValueError(
            f"--city-model: two fits explain the photos alike (heading "
            f"{np.degrees(a.heading_rad) % 360:.0f} and {np.degrees(b.heading_rad) % 360:.0f} "
            f"degrees, scale {a.scale:.4g} and {b.scale:.4g}: "
            f"{fit.best.within(fit.judge_m)} and {fit.runner_up.within(fit.judge_m)} points "
            f"within {fit.judge_m:.2g} m of a surface, ratio "
            f"{fit.runner_up_ratio:.2f}, refused from {config.ambiguity_ratio:g}): the "
            f"photos see too little that is not repeated or symmetric (one wall, a square "
            f"building from all round, a row of like houses); photograph the neighbours or "
            f"corners too, or {FALLBACK}")
