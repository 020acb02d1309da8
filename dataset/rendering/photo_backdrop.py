"""The photo look's backdrop: a belt of trees round the scene, far off, as every outdoor photo
has something on its horizon.

Without it a street capture of a free-standing building sees the building, flat ground and
an empty horizon: consecutive frames round a corner then share no feature structure from
motion can match (docs/measurements/photo-look.md, "The procedural street capture"). The
belt stands on the ground on a vertical cylinder :data:`BACKDROP_GAP_M` outside the scene's
bounding box in plan (centred on it), its top a tree line of crowns between
:data:`TREE_HEIGHT_M` metres. Like the ground it is real to the RGB alone (background to the
labels and depth), and every pattern is a pure function of where a ray meets the cylinder
(the arc length round it and the height) and the look's seed, so it stays put between
views. Cameras outside the cylinder do not see it.
"""

from __future__ import annotations

import numpy as np

from dataset.rendering.look import Look
from dataset.rendering.noise import detail, value_noise
from dataset.rendering.photo_look import HAZE_DISTANCE_M

BACKDROP_GAP_M = 30.0
"""The belt's distance outside the scene's bounding box in plan (half its diagonal)."""
TREE_HEIGHT_M = (7.0, 21.0)
"""Lowest and highest top of the tree line."""

_FOLIAGE_DARK_RGB = np.array([0.10, 0.16, 0.07]) ** 2.2
_FOLIAGE_LIGHT_RGB = np.array([0.34, 0.40, 0.18]) ** 2.2


def backdrop_radius_m(bounds_m: np.ndarray) -> float:
    """Radius (m) of the belt round a scene whose bounding box is ``bounds_m`` (2, 3)."""
    return 0.5 * float(np.hypot(*np.ptp(bounds_m[:, :2], axis=0))) + BACKDROP_GAP_M


def backdrop_hits(origins_m: np.ndarray, dirs_unit: np.ndarray, bounds_m: np.ndarray,
                  seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Where rays (N, 3) from origins inside the belt meet it: ``hit`` (N,) bool, and for
    every ray the distance ``t_m`` along it to the cylinder, the arc length ``arc_m`` round
    it (from +x, counter-clockwise) and the height ``z_m`` there (NaN where the ray is
    vertical or starts outside). A ray hits where 0 <= z < the tree line's top."""
    centre = bounds_m[:, :2].mean(axis=0)
    radius = backdrop_radius_m(bounds_m)
    o = origins_m[:, :2] - centre
    d = dirs_unit[:, :2]
    a = np.einsum("ij,ij->i", d, d)
    b = np.einsum("ij,ij->i", o, d)
    c = np.einsum("ij,ij->i", o, o) - radius**2
    ok = (c < 0) & (a > 1e-12)
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.where(ok, (-b + np.sqrt(b * b - a * c)) / a, np.nan)  # the root ahead
    p = o + t[:, None] * d
    arc_m = radius * np.arctan2(p[:, 1], p[:, 0])
    z_m = origins_m[:, 2] + t * dirs_unit[:, 2]
    hit = ok & (z_m >= 0) & (z_m < tree_line_m(np.nan_to_num(arc_m), seed))
    return hit, t, arc_m, z_m


def tree_line_m(arc_m: np.ndarray, seed: int) -> np.ndarray:
    """(N,) height (m) of the tree line's top at arc lengths ``arc_m``: stands of trees tens
    of metres wide, and crowns a few metres wide on them."""
    lo, hi = TREE_HEIGHT_M
    stands = value_noise(arc_m / 30.0, np.full_like(arc_m, 0.5), seed + 70)
    crowns = value_noise(arc_m / 6.0, np.full_like(arc_m, 1.5), seed + 71)
    twigs = value_noise(arc_m / 1.5, np.full_like(arc_m, 2.5), seed + 72)
    return lo + (hi - lo) * (0.6 * stands + 0.3 * crowns + 0.1 * twigs)


def foliage_albedo(arc_m: np.ndarray, z_m: np.ndarray, seed: int,
                   footprint_m: np.ndarray) -> np.ndarray:
    """(N, 3) linear albedo of the belt at (arc length, height) (m): light and dark foliage
    in clumps from 5 m to 15 cm, darker low down (trunks and shade)."""
    mix = value_noise(arc_m / 5.0, z_m / 5.0, seed + 73)
    tone = 0.6 + 0.5 * value_noise(arc_m / 1.5, z_m / 1.5, seed + 74)
    tone += 0.5 * detail(footprint_m, 0.5) * (value_noise(arc_m / 0.5, z_m / 0.5, seed + 75)
                                              - 0.5)
    tone += 0.3 * detail(footprint_m, 0.15) * (value_noise(arc_m / 0.15, z_m / 0.15, seed + 76)
                                               - 0.5)
    tone *= 1.0 - 0.5 * np.exp(-np.clip(z_m, 0.0, None) / 3.0)
    rgb = _FOLIAGE_DARK_RGB * (1 - mix[:, None]) + _FOLIAGE_LIGHT_RGB * mix[:, None]
    return rgb * np.clip(tone, 0.05, None)[:, None]


def backdrop_radiance(origins_m: np.ndarray, dirs_unit: np.ndarray, bounds_m: np.ndarray,
                      look: Look, pixel_angle_rad: float) -> tuple[np.ndarray, np.ndarray]:
    """``hit`` (N,) and the linear radiance (M, 3) of the belt along the M rays that hit it
    (rays (N, 3) from ``origins_m``): foliage lit by the sun from the side it faces and by
    the sky, hazy with distance."""
    hit, t, arc_m, z_m = backdrop_hits(origins_m, dirs_unit, bounds_m, look.texture_seed)
    t, arc_m, z_m = t[hit], arc_m[hit], z_m[hit]
    p = origins_m[hit, :2] + t[:, None] * dirs_unit[hit, :2]
    inward = bounds_m[:, :2].mean(axis=0) - p
    inward /= np.linalg.norm(inward, axis=1, keepdims=True)
    cos_i = np.clip(-np.einsum("ij,ij->i", dirs_unit[hit, :2], inward), 0.2, 1.0)
    footprint_m = t * pixel_angle_rad / cos_i
    albedo = foliage_albedo(arc_m, z_m, look.texture_seed, footprint_m)
    cos_sun = np.clip(inward @ look.sun_dir[:2], 0.0, None)
    sky = 0.5 * (look.sky_zenith_rgb + look.sky_horizon_rgb)
    irradiance = look.sun_rgb * (0.3 + 0.5 * cos_sun)[:, None] * max(look.sun_dir[2], 0.0) \
        + 0.8 * (0.6 * sky.mean() + 0.4 * sky)
    haze = (1.0 - np.exp(-t / HAZE_DISTANCE_M))[:, None]
    return hit, albedo * irradiance * (1 - haze) + 0.8 * look.sky_horizon_rgb * haze
