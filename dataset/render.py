"""Exact ray-cast rendering of a labelled mesh: z-depth, normals, classes, facade ids and RGB.

One ray per pixel centre goes through Intel Embree (via ``embreex``); the first
hit gives the triangle. Embree works in float32, so the hit distance is then
recomputed in float64 from the hit triangle's plane: depth is exact to float64
rounding, not to Embree's float32 tolerance.

The RGB image (:func:`render_rgb`) shades the same hits; its look lives in
:mod:`dataset.shading`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dataset.camera import Intrinsics, rays_world
from dataset.mesh import LabelledMesh
from dataset.shading import RgbConfig, shade

__all__ = [
    "GroundTruthImages",
    "Raycaster",
    "RgbConfig",
    "render_ground_truth",
    "render_rgb",
    "render_view",
]

# Below this |n . d| a ray grazes its triangle's plane and the plane solve is
# ill-conditioned; Embree's own distance is used there instead.
_GRAZING_COS = 1e-9


class Raycaster:
    """First-hit and occlusion queries on a :class:`LabelledMesh` (Embree BVH, built once).

    Vertices are shifted to the mesh's bounding-box centre before the float32
    conversion, so precision does not depend on where the building stands.

    Attributes
    ----------
    mesh : LabelledMesh
    bounds_m : (2, 3) float64
        Lowest and highest vertex coordinates (world metres).
    face_normals : (F, 3) float64
        Outward unit normal of every face.

    Raises
    ------
    ValueError
        If the mesh has no faces or the Embree backend (``embreex``) is missing.
    """

    def __init__(self, mesh: LabelledMesh):
        if not isinstance(mesh, LabelledMesh):
            raise ValueError(f"Raycaster needs a dataset.mesh.LabelledMesh, got {type(mesh)}")
        if len(mesh.faces) == 0:
            raise ValueError("cannot render a mesh without faces")
        try:
            from embreex import rtcore_scene
            from embreex.mesh_construction import TriangleMesh
        except ImportError as exc:
            raise ValueError(
                "the renderer needs Intel Embree through the embreex package: pip install embreex"
            ) from exc
        self.mesh = mesh
        lo, hi = mesh.vertices_m.min(axis=0), mesh.vertices_m.max(axis=0)
        self.bounds_m = np.stack([lo, hi])
        self._shift_m = 0.5 * (lo + hi)
        self._scene = rtcore_scene.EmbreeScene()
        TriangleMesh(
            self._scene,
            (mesh.vertices_m - self._shift_m).astype(np.float32),
            mesh.faces.astype(np.int32),
        )
        self.face_normals = mesh.face_normals()
        self._plane_offset_m = np.einsum("ij,ij->i", self.face_normals, mesh.triangles_m[:, 0])

    def first_hit(self, origins_m: np.ndarray, dirs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Nearest triangle along each ray.

        Parameters
        ----------
        origins_m : (N, 3) float
            Ray origins, world metres.
        dirs : (N, 3) float
            Ray directions (any non-zero length); distances are in units of ``dirs``.

        Returns
        -------
        face : (N,) int64
            Index of the hit face, -1 where the ray misses.
        t : (N,) float64
            Hit parameter (point = origin + t * dir), ``inf`` where the ray misses.
        """
        o, d = _check_rays(origins_m, dirs)
        hit = self._scene.run(self._to_embree(o), d.astype(np.float32), output=1)
        face = hit["primID"].astype(np.int64)
        t = np.full(len(o), np.inf)
        ok = face >= 0
        f = face[ok]
        n = self.face_normals[f]
        n_dot_d = np.einsum("ij,ij->i", n, d[ok])
        n_dot_o = np.einsum("ij,ij->i", n, o[ok])
        exact = np.abs(n_dot_d) > _GRAZING_COS * np.linalg.norm(d[ok], axis=1)
        t_ok = hit["tfar"][ok].astype(np.float64)
        t_ok[exact] = (self._plane_offset_m[f[exact]] - n_dot_o[exact]) / n_dot_d[exact]
        t[ok] = t_ok
        return face, t

    def occluded(
        self, origins_m: np.ndarray, dirs: np.ndarray, t_max: np.ndarray | float = np.inf
    ) -> np.ndarray:
        """(N,) bool: whether anything lies along each ray within ``t_max`` (units of ``dirs``)."""
        o, d = _check_rays(origins_m, dirs)
        t_far = np.broadcast_to(np.asarray(t_max, dtype=np.float32), (len(o),)).copy()
        res = self._scene.run(
            self._to_embree(o), d.astype(np.float32), dists=t_far, query="OCCLUDED"
        )
        return res >= 0

    def contains(self, points_m: np.ndarray) -> np.ndarray:
        """(N,) bool: whether points lie inside the (closed or bottom-open) mesh.

        A point is inside when most rays cast from it in 14 directions first hit
        a face from behind; rays that escape (an open bottom) do not vote.
        """
        p = np.asarray(points_m, dtype=np.float64).reshape(-1, 3)
        dirs = _PROBE_DIRS
        o = np.repeat(p, len(dirs), axis=0)
        d = np.tile(dirs, (len(p), 1))
        face, _ = self.first_hit(o, d)
        facing = np.einsum("ij,ij->i", self.face_normals[np.maximum(face, 0)], d)
        back = ((face >= 0) & (facing > 0)).reshape(len(p), -1).sum(axis=1)
        front = ((face >= 0) & (facing <= 0)).reshape(len(p), -1).sum(axis=1)
        return back > front

    def _to_embree(self, origins_m: np.ndarray) -> np.ndarray:
        return (origins_m - self._shift_m).astype(np.float32)


def _probe_dirs() -> np.ndarray:
    axes = np.eye(3)
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    # Slightly skewed so that no probe runs exactly along a wall or through an edge.
    d = np.concatenate([axes, -axes, corners / np.sqrt(3)]) + np.array([1e-3, 2e-3, 3e-3])
    return d / np.linalg.norm(d, axis=1, keepdims=True)


_PROBE_DIRS = _probe_dirs()


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
        Semantic class ids (:class:`dataset.classes.SemanticClass`), 0 = background.
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
) -> tuple[GroundTruthImages, np.ndarray]:
    """Ground truth and RGB of one view, as :func:`render_ground_truth` and :func:`render_rgb`
    give them, casting the primary rays once when ``supersampling`` is 1."""
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
        raise ValueError(f"intrinsics must be a dataset.camera.Intrinsics, got {type(intrinsics)}")
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
    behind = (face >= 0) & (t <= 0)
    face[behind], t[behind] = -1, np.inf
    return _ViewHits(rc, origins, dirs, face, t, (intrinsics.height, intrinsics.width))


def _check_rays(origins_m: np.ndarray, dirs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    o = np.asarray(origins_m, dtype=np.float64)
    d = np.asarray(dirs, dtype=np.float64)
    if o.ndim != 2 or o.shape[1] != 3 or o.shape != d.shape:
        raise ValueError(
            f"ray origins and directions must both be (N, 3), got {o.shape} and {d.shape}"
        )
    return o, d


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
