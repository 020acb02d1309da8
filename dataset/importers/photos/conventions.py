"""COLMAP's camera poses in the project's convention, and back.

COLMAP stores ``cam_from_world`` (world -> camera) with the OpenCV camera: x right, y down,
looking along +z. The project stores ``world_from_camera`` (camera -> world) with the OpenGL
camera: x right, y up, looking along -z (docs/ARCHITECTURE.md, "Conventions"). The two cameras
differ by a half turn about x: ``diag(1, -1, -1)``. Both put a pixel's centre at
(u + 0.5, v + 0.5), so intrinsics carry over unchanged.
"""

from __future__ import annotations

import numpy as np

OPENCV_FROM_OPENGL = np.diag([1.0, -1.0, -1.0, 1.0])
"""(4, 4) the OpenGL camera's axes in the OpenCV camera's (its own inverse)."""


def world_from_camera_gl(cam_from_world_cv: np.ndarray) -> np.ndarray:
    """(4, 4) camera-to-world OpenGL pose of a COLMAP ``cam_from_world``, (3, 4) or (4, 4)."""
    m = np.asarray(cam_from_world_cv, dtype=np.float64)
    if m.shape not in ((3, 4), (4, 4)):
        raise ValueError(f"cam_from_world must be 3x4 or 4x4, got shape {m.shape}")
    rot, t = m[:3, :3], m[:3, 3]
    world_from_cam_cv = np.eye(4)
    world_from_cam_cv[:3, :3] = rot.T
    world_from_cam_cv[:3, 3] = -rot.T @ t
    return world_from_cam_cv @ OPENCV_FROM_OPENGL


def cam_from_world_cv(world_from_camera: np.ndarray) -> np.ndarray:
    """(3, 4) COLMAP ``cam_from_world`` of a (4, 4) camera-to-world OpenGL pose."""
    pose = np.asarray(world_from_camera, dtype=np.float64) @ OPENCV_FROM_OPENGL
    rot, centre = pose[:3, :3], pose[:3, 3]
    return np.concatenate([rot.T, (-rot.T @ centre)[:, None]], axis=1)
