"""Facade views of a building: ideal and multi views of each facade, for the 2D methods.

All poses are (4, 4) ``world_from_camera`` matrices (OpenGL convention); every
sampler is deterministic for a given seed. Where each facade is comes from
:mod:`dataset.rendering.facade_patches`. Ideal: on the facade's
normal through its centre, looking straight at it, as near as the whole
facade fits with a margin. Multi: five natural views per facade (azimuth up
to about +-40 deg off the normal, heights from eye level to mid-facade,
several distances), each aimed at the facade's centre and backed off until
the whole facade is in the image.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from dataset.rendering.facade_patches import FacadePatch, facade_patches
from dataset.rendering.render import Raycaster
from envelope.camera import Intrinsics, look_at, project_world_to_image
from envelope.truth import Building


@dataclass(frozen=True)
class FacadeViewConfig:
    """Placement of ideal and multi facade views.

    ``margin``: share of the image (each side) kept free around the facade in ideal
    views. ``sector_deg``: largest angular sector of a curved facade per patch.
    ``multi_count``: views per facade (patch). ``multi_azimuth_deg``: largest azimuth
    off the normal. ``eye_height_m``: lowest camera height. ``multi_distance_factor``:
    distance drawn as a multiple of the ideal view's. ``min_visible_fraction``:
    least share of the facade's surface (sampled at ``visibility_samples`` points)
    seen unoccluded by a multi view; ``ideal_min_visible_fraction`` the same for an
    ideal view, which has no other position to try and so accepts more occlusion
    (balconies in front of the facade). ``max_attempts``: draws per multi view
    before it is dropped.
    """

    margin: float = 0.08
    sector_deg: float = 60.0
    multi_count: int = 5
    multi_azimuth_deg: float = 40.0
    eye_height_m: float = 1.6
    multi_distance_factor: tuple[float, float] = (1.0, 1.5)
    min_visible_fraction: float = 0.6
    ideal_min_visible_fraction: float = 0.3
    visibility_samples: int = 200
    max_attempts: int = 30

    def __post_init__(self) -> None:
        if not 0 <= self.margin < 0.5:
            raise ValueError(f"margin must be in [0, 0.5), got {self.margin}")
        if self.multi_count < 1 or not 0 <= self.multi_azimuth_deg < 90:
            raise ValueError("multi_count must be >= 1 and multi_azimuth_deg in [0, 90)")
        if not 0 < self.multi_distance_factor[0] <= self.multi_distance_factor[1]:
            raise ValueError("multi_distance_factor must satisfy 0 < lo <= hi")
        fractions = (self.min_visible_fraction, self.ideal_min_visible_fraction)
        if not all(0 <= f <= 1 for f in fractions) or self.visibility_samples < 1:
            raise ValueError(
                "min_visible_fraction and ideal_min_visible_fraction must be in [0, 1], "
                "visibility_samples >= 1"
            )


def ideal_views(
    building: Building, raycaster: Raycaster, intrinsics: Intrinsics, *, config: FacadeViewConfig,
) -> list[tuple[int, np.ndarray]]:
    """One (facade_id, pose) per facade (per sector of a curved facade).

    The optical axis is the facade's inward normal through the centre of its
    rectangle; the distance fits the whole rectangle with ``config.margin``. A
    facade whose ideal camera would sit inside the building or see less than
    ``ideal_min_visible_fraction`` of it gets no view (with a warning).
    """
    views = []
    for patch in facade_patches(building, sector_deg=config.sector_deg):
        distance = _fit_distance_m(patch, intrinsics, config.margin)
        eye = patch.centre_m + distance * patch.normal
        pose = look_at(eye, patch.centre_m)
        problem = _facade_view_problem(raycaster, patch, pose, config,
                                       config.ideal_min_visible_fraction)
        if problem:
            warnings.warn(
                f"building {building.truth.id}: facade {patch.facade_id} gets no ideal view "
                f"({problem})",
                stacklevel=2,
            )
            continue
        views.append((patch.facade_id, pose))
    return views


def multi_views(
    building: Building, raycaster: Raycaster, intrinsics: Intrinsics, *,
    config: FacadeViewConfig, seed: int,
) -> list[tuple[int, np.ndarray]]:
    """``config.multi_count`` (facade_id, pose) per facade (per sector of a curved facade).

    View k of a facade sits at an azimuth spread evenly over +-``multi_azimuth_deg``
    (jittered), a height between eye level and mid-facade and a distance of
    ``multi_distance_factor`` times the ideal one, aimed at the facade centre and
    backed off until the facade's rectangle is in the image. A view that cannot
    see enough of its facade after ``max_attempts`` draws is dropped with a warning.
    """
    rng = np.random.default_rng([int(seed) & 0xFFFFFFFF, 0x3A1])
    count = config.multi_count
    spread = np.deg2rad(config.multi_azimuth_deg)
    slots = np.linspace(-spread, spread, count) if count > 1 else np.zeros(1)
    jitter = spread / max(count - 1, 1) / 4
    views = []
    for patch in facade_patches(building, sector_deg=config.sector_deg):
        base = _fit_distance_m(patch, intrinsics, config.margin)
        top = max(config.eye_height_m, float(patch.centre_m[2]))
        for k, slot in enumerate(slots):
            pose, problem = None, ""
            for attempt in range(config.max_attempts):
                # Near its slot first; then anywhere in the range (an L-shape's inner
                # facade is hidden by the other wing on one side).
                azimuth = (slot + rng.uniform(-jitter, jitter) if attempt < config.max_attempts // 3
                           else rng.uniform(-spread, spread))
                eye_z = rng.uniform(config.eye_height_m, top)
                distance = base * rng.uniform(*config.multi_distance_factor)
                pose, problem = _multi_pose(
                    raycaster, intrinsics, config, patch, azimuth, eye_z, distance
                )
                if not problem:
                    break
            if problem:
                warnings.warn(
                    f"building {building.truth.id}: facade {patch.facade_id} multi view "
                    f"{k + 1} dropped ({problem})",
                    stacklevel=2,
                )
                continue
            views.append((patch.facade_id, pose))
    return views


def _multi_pose(
    raycaster: Raycaster, intrinsics: Intrinsics, config: FacadeViewConfig,
    patch: FacadePatch, azimuth: float, eye_z: float, distance: float,
) -> tuple[np.ndarray, str]:
    direction = np.cos(azimuth) * patch.normal + np.sin(azimuth) * patch.right
    for _ in range(12):  # back off until the facade fits; 1.15**12 ~ 5x
        eye = patch.centre_m + distance * direction
        eye[2] = eye_z
        pose = look_at(eye, patch.centre_m)
        if _corners_in_image(patch, intrinsics, pose, margin=0.02):
            return pose, _facade_view_problem(raycaster, patch, pose, config,
                                              config.min_visible_fraction)
        distance *= 1.15
    return pose, "facade does not fit in the image"


def _facade_view_problem(
    raycaster: Raycaster, patch: FacadePatch, pose: np.ndarray, config: FacadeViewConfig,
    min_visible: float,
) -> str:
    eye = pose[:3, 3]
    if raycaster.contains(eye[None])[0]:
        return "camera would be inside the building"
    if not raycaster.open_to_sky(eye[None])[0]:
        return "camera would be under the building (a slab, a balcony, an overhang)"
    points = _facade_samples_m(raycaster, patch, config.visibility_samples)
    to_points = points - eye
    _, t = raycaster.first_hit(np.broadcast_to(eye, to_points.shape), to_points)
    # A sample is seen when nothing stops the ray before it (1 cm slack).
    slack = 0.01 / np.linalg.norm(to_points, axis=1)
    visible = float(np.mean(t >= 1 - slack))
    if visible < min_visible:
        return f"only {visible:.0%} of the facade visible"
    return ""


def _facade_samples_m(raycaster: Raycaster, patch: FacadePatch, count: int) -> np.ndarray:
    """(count, 3) points spread over the patch's faces by area, the same on every call."""
    rng = np.random.default_rng(patch.facade_id)
    tri = raycaster.mesh.triangles_m[patch.face_index]
    areas = raycaster.mesh.face_areas_m2()[patch.face_index]
    pick = rng.choice(len(tri), size=count, p=areas / areas.sum())
    a, b = rng.uniform(size=(2, count))
    flip = a + b > 1
    a[flip], b[flip] = 1 - a[flip], 1 - b[flip]
    t = tri[pick]
    return t[:, 0] + a[:, None] * (t[:, 1] - t[:, 0]) + b[:, None] * (t[:, 2] - t[:, 0])


def _corners_in_image(
    patch: FacadePatch, intrinsics: Intrinsics, pose: np.ndarray, margin: float
) -> bool:
    uv, depth = project_world_to_image(patch.corners_m, intrinsics, pose)
    w, h = intrinsics.width, intrinsics.height
    return bool(
        (depth > 0).all()
        and (uv[:, 0] >= margin * w).all() and (uv[:, 0] <= (1 - margin) * w).all()
        and (uv[:, 1] >= margin * h).all() and (uv[:, 1] <= (1 - margin) * h).all()
    )


def _fit_distance_m(patch: FacadePatch, intrinsics: Intrinsics, margin: float) -> float:
    """Distance from the facade plane at which its rectangle fills the image up to ``margin``."""
    tan_x = min(intrinsics.cx, intrinsics.width - intrinsics.cx) / intrinsics.fx
    tan_y = min(intrinsics.cy, intrinsics.height - intrinsics.cy) / intrinsics.fy
    shrink = 1 - 2 * margin
    return max(
        0.5 * patch.width_m / (tan_x * shrink), 0.5 * patch.height_m / (tan_y * shrink), 1.0
    )
