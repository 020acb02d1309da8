"""Scale and true north from the photos' GPS positions: the similarity in the horizontal
plane that takes the structure-from-motion camera centres (levelled: z up) onto their GPS
positions in metres east and north (docs/importing.md, section 9).

- **Fit**: ``east + i north = a (x + i y) + b`` with complex ``a`` (scale ``|a|``, turn
  ``arg a``: no mirror) and ``b``, least squares (Umeyama's similarity in the plane, in
  closed form).
- **Bad fixes**: every pair of photos gives one exact similarity (all pairs up to
  :data:`MAX_PAIRS`, else that many drawn with a fixed seed); the one with the least
  truncated cost ``sum min(r², OUTLIER_M²)`` over every fix (MSAC) picks the fixes within
  :data:`OUTLIER_M` of it, and least squares over those is refitted until they no longer
  change. Fixes further off are left out and listed.
- **Enough**: at least :data:`MIN_FIXES` fixes kept, spread at least :data:`MIN_SPREAD_M`
  (the RMS horizontal distance of the kept fixes from their mean). A fix errs by about
  :data:`GPS_ERROR_M`; fixes spread over ``d`` metres then give the scale (and the turn, in
  radians) to about ``GPS_ERROR_M / d``, with no gain from many photos, since fixes taken
  minutes apart err alike. :data:`MIN_SPREAD_M` keeps that within :data:`MAX_SCALE_ERROR`.
- **Altitude** is not used: consumer GPS altitude errs by tens of metres; up comes from
  the cameras (:mod:`dataset.importers.photos.metric_frame`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

GPS_ERROR_M = 5.0
"""A consumer receiver's horizontal error beside buildings (3 to 5 m in the open; more in a
street canyon)."""
MAX_SCALE_ERROR = 0.25
"""The largest relative scale error (and turn error, in radians: 14°) accepted."""
MIN_SPREAD_M = GPS_ERROR_M / MAX_SCALE_ERROR
"""20 m: the least RMS spread of the fixes about their mean (module docstring)."""
OUTLIER_M = 3.0 * GPS_ERROR_M
"""A fix further than this from its fitted place is a bad fix (multipath, a stale fix)."""
MIN_FIXES = 3
"""Two fixes fix a similarity exactly; a third is the least that checks it."""
MAX_PAIRS = 5000
"""Pair hypotheses tried at most (all pairs of up to 100 photos)."""
PAIR_SEED = 0
FALLBACK_OPTIONS = "give --known-distance or --known-height instead"


@dataclass(frozen=True)
class PlaneSimilarity:
    """``east_north = scale * turn(heading_rad) @ xy + translation_m``: ``heading_rad``
    counter-clockwise, from the input's x, y to east, north."""

    scale: float
    heading_rad: float
    translation_m: np.ndarray

    def apply(self, xy: np.ndarray) -> np.ndarray:
        """(N, 2) east, north metres of (N, 2) input x, y."""
        z = self.scale * np.exp(1j * self.heading_rad) * _complex(xy) \
            + complex(*self.translation_m)
        return np.column_stack([z.real, z.imag])


@dataclass(frozen=True)
class GpsFit:
    """The fitted similarity, which fixes it kept ((N,) bool), every fix's distance from its
    fitted place ((N,) m) and the kept fixes' RMS spread about their mean (m)."""

    similarity: PlaneSimilarity
    kept: np.ndarray
    residuals_m: np.ndarray
    spread_m: float


def similarity_2d(source_xy: np.ndarray, target_xy: np.ndarray) -> PlaneSimilarity:
    """The least-squares similarity (no mirror) taking (N, 2) ``source_xy`` onto (N, 2)
    ``target_xy``, N >= 2 with two distinct sources."""
    s, t = _complex(source_xy), _complex(target_xy)
    s0, t0 = s - s.mean(), t - t.mean()
    a = np.vdot(s0, t0) / np.vdot(s0, s0).real  # vdot conjugates its first argument
    b = t.mean() - a * s.mean()
    return PlaneSimilarity(float(abs(a)), float(np.angle(a)), np.array([b.real, b.imag]))


def spread_m(east_north: np.ndarray) -> float:
    """The RMS distance (m) of (N, 2) positions from their mean."""
    east_north = np.asarray(east_north, dtype=np.float64)
    return float(np.sqrt(((east_north - east_north.mean(axis=0)) ** 2).sum(axis=1).mean()))


def check_fixes(east_north: np.ndarray, photos: int) -> None:
    """Refuse too few fixes or fixes too close together ((N, 2) metres of the N photos with
    a fix out of ``photos``), before anything is fitted.

    Raises
    ------
    ValueError
        Fewer than :data:`MIN_FIXES` fixes, or a spread under :data:`MIN_SPREAD_M`.
    """
    if len(east_north) < MIN_FIXES:
        raise ValueError(
            f"--gps: {len(east_north)} of {photos} photos carry an EXIF GPS position; at least "
            f"{MIN_FIXES} must (phones write it with location on; messengers and many editors "
            f"strip it): {FALLBACK_OPTIONS}")
    spread = spread_m(east_north)
    if spread < MIN_SPREAD_M:
        raise ValueError(
            f"--gps: the photos' GPS positions spread {spread:.1f} m (RMS about their mean), "
            f"under the {MIN_SPREAD_M:g} m needed: a fix errs by about {GPS_ERROR_M:g} m, so "
            f"the scale would err by {GPS_ERROR_M / max(spread, 1e-9):.0%} or more. Photograph "
            f"from further round the building, or {FALLBACK_OPTIONS}")


def fit_gps(source_xy: np.ndarray, east_north: np.ndarray,
            photos: int | None = None) -> GpsFit:
    """The similarity from (N, 2) levelled camera centres to their (N, 2) GPS metres,
    robust to bad fixes (module docstring); ``photos``: how many photos the N fixes are of,
    for the messages (default N).

    Raises
    ------
    ValueError
        Too few fixes, too close together (:func:`check_fixes`), or fewer than
        :data:`MIN_FIXES` agreeing within :data:`OUTLIER_M`.
    """
    source, target = _complex(source_xy), _complex(east_north)
    photos = len(target) if photos is None else photos
    check_fixes(east_north, photos)
    first, second = _pairs(len(target))
    ds = source[second] - source[first]
    usable = np.abs(ds) > 1e-12 * max(1.0, float(np.abs(source).max()))
    first, second, ds = first[usable], second[usable], ds[usable]
    if len(ds) == 0:
        raise ValueError("--gps: the cameras with a GPS position were all at one place in "
                         f"structure from motion: {FALLBACK_OPTIONS}")
    a = (target[second] - target[first]) / ds
    b = target[first] - a * source[first]
    cost = np.minimum(np.abs(a[:, None] * source[None] + b[:, None] - target[None]) ** 2,
                      OUTLIER_M ** 2).sum(axis=1)
    best = int(np.argmin(cost))
    kept = np.abs(a[best] * source + b[best] - target) <= OUTLIER_M
    for _ in range(len(target)):  # refit until the kept fixes settle (each step keeps fewer or
        if kept.sum() < MIN_FIXES:  # as many or changes them: a few steps in practice)
            break
        similarity = similarity_2d(np.asarray(source_xy)[kept], np.asarray(east_north)[kept])
        residuals = np.linalg.norm(similarity.apply(source_xy) - east_north, axis=1)
        now = residuals <= OUTLIER_M
        if np.array_equal(now, kept):
            break
        kept = now
    if kept.sum() < MIN_FIXES:
        raise ValueError(
            f"--gps: only {int(kept.sum())} of {len(target)} GPS positions agree with the "
            f"photos' layout within {OUTLIER_M:g} m; at least {MIN_FIXES} must: "
            f"{FALLBACK_OPTIONS}")
    check_fixes(np.asarray(east_north)[kept], photos)
    return GpsFit(similarity, kept, residuals, spread_m(np.asarray(east_north)[kept]))


def _pairs(n: int) -> tuple[np.ndarray, np.ndarray]:
    first, second = np.triu_indices(n, k=1)
    if len(first) > MAX_PAIRS:
        chosen = np.sort(np.random.default_rng(PAIR_SEED).choice(len(first), MAX_PAIRS,
                                                                 replace=False))
        first, second = first[chosen], second[chosen]
    return first, second


def _complex(xy: np.ndarray | Sequence) -> np.ndarray:
    xy = np.asarray(xy, dtype=np.float64)
    return xy[:, 0] + 1j * xy[:, 1]
