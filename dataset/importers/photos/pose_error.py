"""How far recovered camera poses are from true ones: a similarity (Umeyama) takes the
recovered camera centres onto the true ones; what is left after it is the pose error, and
its scale is the scale error of a metric reconstruction. For checking the photos source on
renders whose true poses are known (tests and bench/photos_from_renders.py), never used by
the source itself.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class PoseErrors:
    """Errors of N recovered poses against the true ones, after :func:`similarity_alignment`.

    ``scale``: the similarity's scale (1 for a reconstruction in true metres);
    ``up_deg``: the angle its rotation turns the z axis by (0 for z up in both);
    ``rotation_deg``, ``position_m``: (N,) each camera's orientation and centre error.
    """

    scale: float
    up_deg: float
    rotation_deg: np.ndarray
    position_m: np.ndarray

    @property
    def scale_error(self) -> float:
        """Relative scale error, |scale - 1| (0.01 is 1 %)."""
        return abs(self.scale - 1.0)


def similarity_alignment(source_m: np.ndarray, target_m: np.ndarray
                         ) -> tuple[float, np.ndarray, np.ndarray]:
    """Umeyama's least-squares similarity (scale, (3, 3) rotation, (3,) translation) taking
    (N, 3) ``source_m`` points onto ``target_m`` (N >= 3, not all on a line)."""
    source_m, target_m = np.asarray(source_m, float), np.asarray(target_m, float)
    if source_m.shape != target_m.shape or source_m.ndim != 2 or source_m.shape[1] != 3 \
            or len(source_m) < 3:
        raise ValueError(f"need two (N, 3) point sets of one shape with N >= 3, got "
                         f"{source_m.shape} and {target_m.shape}")
    mu_s, mu_t = source_m.mean(axis=0), target_m.mean(axis=0)
    s, t = source_m - mu_s, target_m - mu_t
    u, d, vt = np.linalg.svd(t.T @ s / len(source_m))
    sign = np.diag([1.0, 1.0, np.sign(np.linalg.det(u @ vt))])
    rotation = u @ sign @ vt
    scale = float(np.trace(np.diag(d) @ sign) / (s ** 2).sum(axis=1).mean())
    return scale, rotation, mu_t - scale * rotation @ mu_s


def rotation_angle_deg(rotation: np.ndarray) -> float:
    """Angle (degrees) of a (3, 3) rotation matrix."""
    return float(np.degrees(np.arccos(np.clip((np.trace(rotation) - 1) / 2, -1, 1))))


def pose_errors(recovered_world_from_camera: np.ndarray,
                true_world_from_camera: np.ndarray) -> PoseErrors:
    """Errors of (N, 4, 4) recovered camera-to-world poses against the (N, 4, 4) true ones
    of the same cameras (same convention), after the similarity that best takes the
    recovered camera centres onto the true ones."""
    posed = np.asarray(recovered_world_from_camera, float)
    true = np.asarray(true_world_from_camera, float)
    scale, rotation, shift = similarity_alignment(posed[:, :3, 3], true[:, :3, 3])
    rotation_deg = np.array([rotation_angle_deg(t[:3, :3].T @ rotation @ p[:3, :3])
                             for p, t in zip(posed, true)])
    position_m = np.linalg.norm(scale * posed[:, :3, 3] @ rotation.T + shift - true[:, :3, 3],
                                axis=1)
    up_deg = float(np.degrees(np.arccos(np.clip(rotation[2, 2], -1.0, 1.0))))
    return PoseErrors(scale, up_deg, rotation_deg, position_m)
