"""Pinhole cameras in the OpenGL/nerfstudio convention (camera looks along -z, +y up).

Pixel (u, v) has column u and row v (v grows downward); its centre is at
(u + 0.5, v + 0.5) in the same continuous image coordinates as cx, cy.
Depth is z-depth along the optical axis in metres (docs/DESIGN.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Intrinsics:
    """Pinhole intrinsics in pixels; ``width`` x ``height`` image."""

    fx: float
    fy: float
    cx: float
    cy: float
    width: int
    height: int

    def __post_init__(self) -> None:
        if self.width <= 0 or self.height <= 0:
            raise ValueError(f"image size must be positive, got {self.width}x{self.height}")
        if self.fx <= 0 or self.fy <= 0:
            raise ValueError(f"focal lengths must be positive, got fx={self.fx}, fy={self.fy}")

    @property
    def K(self) -> np.ndarray:
        """(3, 3) float64 calibration matrix (OpenCV form, image y down)."""
        return np.array([[self.fx, 0, self.cx], [0, self.fy, self.cy], [0, 0, 1]], dtype=np.float64)

    @staticmethod
    def from_fov(width: int, height: int, fov_x_deg: float) -> Intrinsics:
        """Square-pixel intrinsics with horizontal field of view ``fov_x_deg``, centred."""
        f = 0.5 * width / np.tan(np.deg2rad(fov_x_deg) / 2)
        return Intrinsics(f, f, width / 2, height / 2, width, height)

    def scaled(self, factor: float) -> Intrinsics:
        """Intrinsics of the same camera with the image resized by ``factor``."""
        return Intrinsics(
            self.fx * factor, self.fy * factor, self.cx * factor, self.cy * factor,
            round(self.width * factor), round(self.height * factor),
        )


def pixel_centres(intrinsics: Intrinsics) -> np.ndarray:
    """(H, W, 2) float64 continuous (u, v) coordinates of every pixel centre."""
    u = np.arange(intrinsics.width, dtype=np.float64) + 0.5
    v = np.arange(intrinsics.height, dtype=np.float64) + 0.5
    uu, vv = np.meshgrid(u, v)
    return np.stack([uu, vv], axis=-1)


def camera_dirs_from_pixels(uv: np.ndarray, intrinsics: Intrinsics) -> np.ndarray:
    """Camera-frame ray directions with z = -1 (not unit) through image points.

    Parameters
    ----------
    uv : (..., 2) float
        Continuous image coordinates (pixel centres are at +0.5).

    Returns
    -------
    (..., 3) float64 directions (x, y, -1) in the OpenGL camera frame; a point at
    z-depth d along the ray is ``d * dir``.
    """
    uv = np.asarray(uv, dtype=np.float64)
    x = (uv[..., 0] - intrinsics.cx) / intrinsics.fx
    y = -(uv[..., 1] - intrinsics.cy) / intrinsics.fy
    return np.stack([x, y, -np.ones_like(x)], axis=-1)


def rays_world(
    intrinsics: Intrinsics, world_from_camera: np.ndarray, uv: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """World-frame rays through pixel centres (or through ``uv``).

    Parameters
    ----------
    world_from_camera : (4, 4) float
        Camera-to-world pose, OpenGL convention.
    uv : (..., 2) float, optional
        Image points; default all pixel centres, shape (H, W, 2).

    Returns
    -------
    origins_m : (..., 3) float64
    dirs_z : (..., 3) float64
        World directions scaled so that one unit of travel is one metre of
        z-depth (``origin + d * dirs_z`` is the point at z-depth d).
    """
    pose = _check_pose(world_from_camera)
    if uv is None:
        uv = pixel_centres(intrinsics)
    d_cam = camera_dirs_from_pixels(uv, intrinsics)
    dirs = d_cam @ pose[:3, :3].T
    origins = np.broadcast_to(pose[:3, 3], dirs.shape).copy()
    return origins, dirs


def unproject_depth_to_world(
    uv: np.ndarray, depth_z_m: np.ndarray, intrinsics: Intrinsics, world_from_camera: np.ndarray
) -> np.ndarray:
    """World points (m) of image points with known z-depth.

    Parameters
    ----------
    uv : (..., 2) float
    depth_z_m : (...) float
        z-depth in metres.

    Returns
    -------
    (..., 3) float64 world points.
    """
    origins, dirs = rays_world(intrinsics, world_from_camera, uv)
    return origins + np.asarray(depth_z_m, dtype=np.float64)[..., None] * dirs


def project_world_to_image(
    points_world_m: np.ndarray, intrinsics: Intrinsics, world_from_camera: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Project world points into the image.

    Parameters
    ----------
    points_world_m : (..., 3) float

    Returns
    -------
    uv : (..., 2) float64 continuous image coordinates
    depth_z_m : (...) float64 z-depth (negative: behind the camera)
    """
    pose = _check_pose(world_from_camera)
    camera_from_world = np.linalg.inv(pose)
    p = np.asarray(points_world_m, dtype=np.float64)
    pc = p @ camera_from_world[:3, :3].T + camera_from_world[:3, 3]
    depth = -pc[..., 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        u = intrinsics.fx * pc[..., 0] / depth + intrinsics.cx
        v = -intrinsics.fy * pc[..., 1] / depth + intrinsics.cy
    return np.stack([u, v], axis=-1), depth


def look_at(eye_m: np.ndarray, target_m: np.ndarray, up: np.ndarray | None = None) -> np.ndarray:
    """(4, 4) world_from_camera pose at ``eye_m`` looking at ``target_m`` (OpenGL convention).

    ``up`` defaults to world +z; when the view is vertical, world +y is used instead.
    """
    eye = np.asarray(eye_m, dtype=np.float64)
    forward = np.asarray(target_m, dtype=np.float64) - eye
    norm = np.linalg.norm(forward)
    if norm == 0:
        raise ValueError("look_at: eye and target coincide")
    forward /= norm
    up = np.array([0.0, 0.0, 1.0]) if up is None else np.asarray(up, dtype=np.float64)
    if abs(np.dot(forward, up / np.linalg.norm(up))) > 0.999:
        up = np.array([0.0, 1.0, 0.0])
    right = np.cross(forward, up)
    right /= np.linalg.norm(right)
    true_up = np.cross(right, forward)
    pose = np.eye(4)
    pose[:3, 0] = right
    pose[:3, 1] = true_up
    pose[:3, 2] = -forward
    pose[:3, 3] = eye
    return pose


def _check_pose(world_from_camera: np.ndarray) -> np.ndarray:
    pose = np.asarray(world_from_camera, dtype=np.float64)
    if pose.shape != (4, 4):
        raise ValueError(f"world_from_camera must be a (4, 4) matrix, got shape {pose.shape}")
    return pose
