"""Orbit views of a building (train/eval; the paper's Algorithm 1) and the check every view
passes.

All poses are (4, 4) ``world_from_camera`` matrices (OpenGL convention). Every
sampler is deterministic for a given seed.

Orbit views (train/eval): cameras on a sphere around the point of interest
(the centre of the mesh's bounding box), looking at it. Each candidate is
checked on a low-resolution depth render (:func:`orbit_view_failures`); a
failing candidate is adjusted (farther when the building touches the border or
the camera is inside or too close, nearer when the building is too small,
higher when the camera is below ground) a bounded number of times, then
redrawn. Candidates whose viewing direction is too close to an accepted one's
are redrawn too (a Poisson-disc spread over the sphere band).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from dataset.rendering.render import Raycaster, render_ground_truth
from envelope.camera import Intrinsics, look_at
from envelope.truth import Building

ViewFailure = Literal[
    "below_ground", "inside_building", "under_building", "too_close", "not_visible",
    "touches_border", "too_small",
]


@dataclass(frozen=True)
class OrbitConfig:
    """Algorithm 1's sampling ranges and boundary conditions.

    ``elevation_deg``: camera elevation above the point of interest, drawn uniformly.
    ``radius_factor``: radius drawn as a multiple of the radius at which the
    bounding sphere just fits the image. ``margin``: share of the image width
    (height) at each border that must show no building. ``min_coverage``: least
    share of pixels showing the building. ``min_camera_height_m``: least camera
    height above the ground. ``min_clearance_m``: least z-depth of any visible
    surface. ``separation``: least angle between two views' directions from the
    point of interest, as a share of the mean spacing sqrt(band solid angle / n).
    ``check_resolution``: width of the depth render the conditions are checked on.
    ``max_adjustments``: fixes tried on one candidate; ``max_attempts``: candidates
    drawn per view before the building counts as impossible to frame.
    """

    elevation_deg: tuple[float, float] = (-10.0, 65.0)
    radius_factor: tuple[float, float] = (0.9, 1.5)
    margin: float = 0.04
    min_coverage: float = 0.05
    min_camera_height_m: float = 1.5
    min_clearance_m: float = 1.0
    separation: float = 0.5
    check_resolution: int = 64
    max_adjustments: int = 10
    max_attempts: int = 60

    def __post_init__(self) -> None:
        lo, hi = self.elevation_deg
        if not -90 < lo <= hi < 90:
            raise ValueError(f"elevation_deg must satisfy -90 < lo <= hi < 90, got {lo, hi}")
        if not 0 < self.radius_factor[0] <= self.radius_factor[1]:
            raise ValueError(f"radius_factor must satisfy 0 < lo <= hi, got {self.radius_factor}")
        if not 0 <= self.margin < 0.5 or not 0 <= self.min_coverage < 1:
            raise ValueError("margin must be in [0, 0.5) and min_coverage in [0, 1)")
        if self.check_resolution < 8 or self.max_adjustments < 0 or self.max_attempts < 1:
            raise ValueError("check_resolution >= 8, max_adjustments >= 0, max_attempts >= 1")


def point_of_interest_m(raycaster: Raycaster) -> np.ndarray:
    """(3,) centre of the mesh's bounding box, the point orbit views look at."""
    return raycaster.bounds_m.mean(axis=0)


def orbit_view_failures(
    raycaster: Raycaster, intrinsics: Intrinsics, world_from_camera: np.ndarray,
    config: OrbitConfig,
) -> tuple[ViewFailure, ...]:
    """Boundary conditions a pose breaks (empty when it meets them all).

    Checked on a depth render ``config.check_resolution`` pixels wide: camera at
    least ``min_camera_height_m`` above the ground, outside the building and not under
    it (a vertical ray up from the camera leaves the mesh);
    building visible, no nearer than ``min_clearance_m``, clear of a border band of
    ``margin`` of the image, covering at least ``min_coverage`` of the pixels.
    """
    pose = np.asarray(world_from_camera, dtype=np.float64)
    failures: list[ViewFailure] = []
    eye = pose[:3, 3]
    if eye[2] < config.min_camera_height_m:
        failures.append("below_ground")
    if raycaster.contains(eye[None])[0]:
        failures.append("inside_building")
    elif not raycaster.open_to_sky(eye[None])[0]:
        failures.append("under_building")  # under a slab, a balcony, an overhang
    small = intrinsics.scaled(config.check_resolution / intrinsics.width)
    depth = render_ground_truth(raycaster, small, pose).depth_z_m
    hit = depth > 0
    if not hit.any():
        return (*failures, "not_visible")
    if depth[hit].min() < config.min_clearance_m:
        failures.append("too_close")
    bx = int(np.ceil(config.margin * small.width))
    by = int(np.ceil(config.margin * small.height))
    inner = np.zeros_like(hit)
    inner[by : small.height - by, bx : small.width - bx] = True
    if (hit & ~inner).any():
        failures.append("touches_border")
    if hit.mean() < config.min_coverage:
        failures.append("too_small")
    return tuple(failures)


def sample_orbit_views(
    building: Building, raycaster: Raycaster, intrinsics: Intrinsics, n: int, *,
    config: OrbitConfig, seed: int,
) -> list[np.ndarray]:
    """``n`` orbit poses meeting :func:`orbit_view_failures`'s conditions (Algorithm 1).

    Raises
    ------
    ValueError
        If ``n < 1`` or no valid pose is found within ``config.max_attempts`` draws
        for some view (the building cannot be framed).
    """
    if n < 1:
        raise ValueError(f"need at least one orbit view, got n={n}")
    poi = point_of_interest_m(raycaster)
    radius_fit = _sphere_fit_radius_m(raycaster, intrinsics, config.margin)
    lo, hi = np.deg2rad(config.elevation_deg)
    band_sr = 2 * np.pi * (np.sin(hi) - np.sin(lo)) if hi > lo else 4 * np.pi / n
    min_angle = config.separation * np.sqrt(band_sr / n)
    rng = np.random.default_rng([int(seed) & 0xFFFFFFFF, 0x0B17])
    poses: list[np.ndarray] = []
    directions: list[np.ndarray] = []
    for index in range(n):
        last: tuple[str, ...] = ()
        for _ in range(config.max_attempts):
            azimuth, elevation = rng.uniform(0, 2 * np.pi), rng.uniform(lo, hi)
            radius = radius_fit * rng.uniform(*config.radius_factor)
            if _too_near(_unit(azimuth, elevation), directions, min_angle):
                last = ("too near an earlier view",)
                continue
            pose, last = _adjust_orbit(
                raycaster, intrinsics, config, poi, azimuth, elevation, radius, hi
            )
            if last:
                continue
            direction = _unit(azimuth, _elevation_of(pose, poi))
            if _too_near(direction, directions, min_angle):
                last = ("too near an earlier view",)
                continue
            poses.append(pose)
            directions.append(direction)
            break
        else:
            raise ValueError(
                f"cannot frame building {building.truth.id!r}: no valid orbit view "
                f"{index + 1}/{n} after {config.max_attempts} draws (last failure: "
                f"{', '.join(last)}); check the mesh is in metres and stands on z = 0, or "
                "relax OrbitConfig"
            )
    return poses


def _adjust_orbit(
    raycaster: Raycaster, intrinsics: Intrinsics, config: OrbitConfig, poi: np.ndarray,
    azimuth: float, elevation: float, radius: float, max_elevation: float,
) -> tuple[np.ndarray, tuple[str, ...]]:
    """Fix a candidate step by step (farther, nearer, higher); the pose and what still fails."""
    for _ in range(config.max_adjustments + 1):
        eye = poi + radius * _unit(azimuth, elevation)
        pose = look_at(eye, poi)
        failures = orbit_view_failures(raycaster, intrinsics, pose, config)
        if not failures:
            return pose, ()
        if "below_ground" in failures:
            elevation = min(elevation + np.deg2rad(5.0), max_elevation)
        if {"inside_building", "under_building", "too_close"} & set(failures):
            radius *= 1.25
        elif "touches_border" in failures:
            radius *= 1.15
        elif {"too_small", "not_visible"} & set(failures):
            radius /= 1.15
    return pose, failures


def _sphere_fit_radius_m(raycaster: Raycaster, intrinsics: Intrinsics, margin: float) -> float:
    """Camera distance at which the bounding sphere of the mesh fits inside the margins."""
    lo, hi = raycaster.bounds_m
    sphere = 0.5 * float(np.linalg.norm(hi - lo))
    tan_half = min(intrinsics.cx / intrinsics.fx, intrinsics.cy / intrinsics.fy)
    half_angle = np.arctan(tan_half * (1 - 2 * margin))
    return sphere / np.sin(half_angle)


def _unit(azimuth: float, elevation: float) -> np.ndarray:
    return np.array([
        np.cos(elevation) * np.cos(azimuth), np.cos(elevation) * np.sin(azimuth), np.sin(elevation)
    ])


def _elevation_of(pose: np.ndarray, poi: np.ndarray) -> float:
    d = pose[:3, 3] - poi
    return float(np.arcsin(d[2] / np.linalg.norm(d)))


def _too_near(direction: np.ndarray, accepted: list[np.ndarray], min_angle: float) -> bool:
    if not accepted:
        return False
    cos = np.clip(np.asarray(accepted) @ direction, -1.0, 1.0)
    return bool(np.arccos(cos.max()) < min_angle)
