"""Exact ray-cast rendering of a labelled mesh: z-depth, normals, classes, facade ids and RGB.

One ray per pixel centre goes through Intel Embree (via ``embreex``); the first
hit gives the triangle. Embree works in float32, so the hit distance is then
recomputed in float64 from the hit triangle's plane: depth is exact to float64
rounding, not to Embree's float32 tolerance.

The world's ground is the plane z = 0 (docs/DESIGN.md): a surface hit below it is underground
and the pixel shows the ground (an imported building's foundations are not seen).

The RGB image (:func:`render_rgb`) shades the same hits; its look lives in
:mod:`dataset.rendering.shading`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dataset.rendering.shading import RgbConfig, shade
from dataset.rendering.textures import TextureSet
from envelope.camera import Intrinsics, rays_world
from envelope.geometry.raycast import Raycaster
from envelope.mesh import LabelledMesh

GROUND_Z_M = 0.0
GROUND_TOLERANCE_M = 1e-6  # hits this far below the ground still count (float round-off)

__all__ = [
    "GroundTruthImages",
    "Raycaster",
    "RgbConfig",
    "render_ground_truth",
    "render_rgb",
    "render_view",
]


@dataclass(frozen=True)
class GroundTruthImages:
    """Exact per-pixel ground truth of one view (hit at each pixel centre).

    Attributes
    ----------
    depth_z_m : (H, W) float32
        z-depth along the optical axis in metres, 0 where no surface.
    normals_world : (H, W, 3) float32
        Unit outward face normals in the world frame, zero where no surface.
    labels : (H, W) uint8
        Semantic class ids (:class:`envelope.classes.SemanticClass`), 0 = background.
    facade_ids : (H, W) int32
        Facade id of the hit face, 0 = none.
    """

    depth_z_m: np.ndarray
    normals_world: np.ndarray
    labels: np.ndarray
    facade_ids: np.ndarray


def render_ground_truth(
    mesh: LabelledMesh | Raycaster, intrinsics: Intrinsics, world_from_camera: np.ndarray
) -> GroundTruthImages:
    """Render z-depth, normals, class ids and facade ids of one pinhole view.

    Parameters
    ----------
    mesh : LabelledMesh or Raycaster
        Pass a :class:`Raycaster` to reuse its BVH across views.
    intrinsics : Intrinsics
    world_from_camera : (4, 4) float
        Camera-to-world pose, OpenGL convention (looks along -z).
    """
    hits = _cast_view(mesh, intrinsics, world_from_camera)
    return hits.images


def render_rgb(
    mesh: LabelledMesh | Raycaster,
    intrinsics: Intrinsics,
    world_from_camera: np.ndarray,
    *,
    config: RgbConfig | None = None,
    seed: int = 0,
    supersampling: int = 1,
) -> np.ndarray:
    """Render a shaded (H, W, 3) uint8 RGB image of one pinhole view.

    ``seed`` picks the building's look (sun, sky, materials); use one seed for all
    views of a building so they agree. ``supersampling`` s renders s x s rays per
    pixel and averages them (anti-aliasing); labels and depth are never supersampled.
    """
    return render_view(mesh, intrinsics, world_from_camera, config=config, seed=seed,
                       supersampling=supersampling)[1]


def render_view(
    mesh: LabelledMesh | Raycaster,
    intrinsics: Intrinsics,
    world_from_camera: np.ndarray,
    *,
    config: RgbConfig | None = None,
    seed: int = 0,
    supersampling: int = 1,
    textures: TextureSet | None = None,
) -> tuple[GroundTruthImages, np.ndarray]:
    """Ground truth and RGB of one view, as :func:`render_ground_truth` and :func:`render_rgb`
    give them, casting the primary rays once when ``supersampling`` is 1. ``textures``: the
    mesh faces' own materials for the RGB (:mod:`dataset.rendering.textures`)."""
    if not isinstance(supersampling, int | np.integer) or supersampling < 1:
        raise ValueError(f"supersampling must be an integer >= 1, got {supersampling!r}")
    config = RgbConfig() if config is None else config
    s = int(supersampling)
    fine = intrinsics.scaled(s) if s > 1 else intrinsics
    hits = _cast_view(mesh, fine, world_from_camera)
    truth = hits.images if s == 1 else render_ground_truth(hits.raycaster, intrinsics,
                                                            world_from_camera)
    rgb_linear = shade(
        hits.raycaster,
        origins_m=hits.origins_m,
        dirs=hits.dirs,
        face=hits.face,
        t=hits.t,
        config=config,
        seed=seed,
        pixel_angle_rad=1.0 / max(fine.fx, fine.fy),
        textures=textures,
    ).reshape(fine.height, fine.width, 3)
    if s > 1:
        h, w = intrinsics.height, intrinsics.width
        rgb_linear = rgb_linear[: h * s, : w * s].reshape(h, s, w, s, 3).mean(axis=(1, 3))
    return truth, _to_srgb8(rgb_linear, config.exposure)


@dataclass(frozen=True)
class _ViewHits:
    raycaster: Raycaster
    origins_m: np.ndarray  # (N, 3)
    dirs: np.ndarray  # (N, 3), one unit of t = one metre of z-depth
    face: np.ndarray  # (N,) int64, -1 = miss
    t: np.ndarray  # (N,) float64 z-depth, inf = miss
    shape: tuple[int, int]

    @property
    def images(self) -> GroundTruthImages:
        rc, hit = self.raycaster, self.face >= 0
        f = np.where(hit, self.face, 0)
        depth = np.where(hit, self.t, 0.0).astype(np.float32)
        normals = np.where(hit[:, None], rc.face_normals[f], 0.0).astype(np.float32)
        labels = np.where(hit, rc.mesh.face_label[f], 0).astype(np.uint8)
        facades = np.where(hit, rc.mesh.face_facade[f], 0).astype(np.int32)
        h, w = self.shape
        return GroundTruthImages(
            depth.reshape(h, w), normals.reshape(h, w, 3), labels.reshape(h, w),
            facades.reshape(h, w),
        )


def _cast_view(
    mesh: LabelledMesh | Raycaster, intrinsics: Intrinsics, world_from_camera: np.ndarray
) -> _ViewHits:
    rc = mesh if isinstance(mesh, Raycaster) else Raycaster(mesh)
    if not isinstance(intrinsics, Intrinsics):
        raise ValueError(
            f"intrinsics must be a envelope.camera.Intrinsics, got {type(intrinsics)}")
    pose = np.asarray(world_from_camera, dtype=np.float64)
    if pose.shape != (4, 4) or not np.isfinite(pose).all():
        raise ValueError(
            f"world_from_camera must be a finite (4, 4) matrix, got shape {pose.shape}"
        )
    rot = pose[:3, :3]
    if not np.allclose(rot.T @ rot, np.eye(3), atol=1e-6):
        raise ValueError("world_from_camera must hold a rotation (orthonormal 3x3 block)")
    origins, dirs = rays_world(intrinsics, pose)
    origins, dirs = origins.reshape(-1, 3), dirs.reshape(-1, 3)
    face, t = rc.first_hit(origins, dirs)
    # A triangle the camera sits in front of can only be hit at t > 0; guard rounding.
    # Below z = 0 is the ground: what an imported building has below grade is not seen.
    hit_z = np.where(face >= 0, origins[:, 2] + np.where(face >= 0, t, 0.0) * dirs[:, 2], 0.0)
    behind = (face >= 0) & ((t <= 0) | (hit_z < GROUND_Z_M - GROUND_TOLERANCE_M))
    face[behind], t[behind] = -1, np.inf
    return _ViewHits(rc, origins, dirs, face, t, (intrinsics.height, intrinsics.width))


def _to_srgb8(rgb_linear: np.ndarray, exposure: float) -> np.ndarray:
    # Soft shoulder instead of a hard clip keeps sunlit highlights from flattening.
    x = 1.0 - np.exp(-np.maximum(rgb_linear, 0.0) * exposure)
    index = (x * (_SRGB_LUT_SIZE - 1) + 0.5).astype(np.intp)
    return _SRGB_LUT[np.clip(index, 0, _SRGB_LUT_SIZE - 1)]


def _srgb_lut(size: int) -> np.ndarray:
    """8-bit sRGB code of ``size`` evenly spaced linear values in [0, 1] (a power per pixel is
    slow; 16384 steps keep the error under a quarter of a code)."""
    x = np.linspace(0.0, 1.0, size)
    srgb = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    return np.clip(np.round(srgb * 255.0), 0, 255).astype(np.uint8)


_SRGB_LUT_SIZE = 16384
_SRGB_LUT = _srgb_lut(_SRGB_LUT_SIZE)
