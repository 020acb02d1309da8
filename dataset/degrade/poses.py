"""Camera-pose noise of structure from motion: a fixed-size rotation and translation."""

from __future__ import annotations

import numpy as np

TRANSLATION_M_PER_DEG = 0.1  # a pose error of s degrees comes with 0.1 s metres of shift


def rotation_about_axis(axis: np.ndarray, angle_rad: float) -> np.ndarray:
    """(3, 3) rotation by ``angle_rad`` about the unit vector ``axis`` (Rodrigues)."""
    a = np.asarray(axis, dtype=np.float64)
    a = a / np.linalg.norm(a)
    cross = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(angle_rad) * cross + (1 - np.cos(angle_rad)) * cross @ cross


def perturb_pose(
    world_from_camera: np.ndarray, rotation_deg: float, translation_m: float,
    rng: np.random.Generator,
) -> np.ndarray:
    """(4, 4) pose rotated by exactly ``rotation_deg`` about a uniformly random axis through
    the camera centre and moved by exactly ``translation_m`` in a uniformly random direction.

    A point at distance r from the camera then moves by |t| (rotation 0) or by
    2 r sin(theta / 2) sin(phi), phi the angle between the axis and the point (t = 0).
    """
    pose = np.asarray(world_from_camera, dtype=np.float64).copy()
    axis, direction = rng.standard_normal(3), rng.standard_normal(3)
    if rotation_deg > 0:
        pose[:3, :3] = rotation_about_axis(axis, np.radians(rotation_deg)) @ pose[:3, :3]
    if translation_m > 0:
        pose[:3, 3] += translation_m * direction / np.linalg.norm(direction)
    return pose


def pose_noise(world_from_camera: np.ndarray, degrees: float,
               rng: np.random.Generator) -> np.ndarray:
    """The ``pose`` degradation of one camera: ``degrees`` of rotation and
    ``TRANSLATION_M_PER_DEG * degrees`` metres of shift (0 = the same pose)."""
    if degrees <= 0:
        return np.asarray(world_from_camera, dtype=np.float64).copy()
    return perturb_pose(world_from_camera, degrees, TRANSLATION_M_PER_DEG * degrees, rng)
