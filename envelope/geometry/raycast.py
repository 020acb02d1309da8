"""The project's one ray caster: embree first-hit and occlusion queries, and one inside rule.

Everything that casts rays at a building -- rendering (:mod:`dataset.rendering.render`), visibility
from outside (:mod:`envelope.geometry.visibility`), footprint sections
(:mod:`dataset.rendering.section`),
camera checks (:mod:`dataset.rendering.orbit_views`) and the importers -- goes through
:class:`Raycaster`,
so they all see the same hits.

**Inside rule.** A point is inside the building when its generalised winding number
(:func:`winding_numbers`: the solid angle the mesh subtends at the point, over 4 pi) is at
least 1/2. For a closed, outward-oriented body that is 1 inside and 0 outside; for a mesh of
many such bodies that touch or overlap it counts the bodies around the point, so inside is
the union of the bodies. It needs no watertight surface, no vertex merge and no ray parity,
and it is computed in float64 with a fixed summation order: the same points give the same
decisions to the last digit on every run.
"""

from __future__ import annotations

import numpy as np

from envelope.mesh import LabelledMesh

# Below this |n . d| a ray grazes its triangle's plane and the plane solve is
# ill-conditioned; Embree's own distance is used there instead.
_GRAZING_COS = 1e-9
INSIDE_WINDING = 0.5
"""A point is inside when its winding number is at least this."""
WINDING_BATCH_ELEMENTS = 1 << 21
"""Point x face pairs per winding-number batch (bounds memory: ~0.2 GB of float64)."""


class Raycaster:
    """First-hit, occlusion and inside queries on a :class:`LabelledMesh` (Embree BVH, built once).

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
            raise ValueError(f"Raycaster needs a envelope.mesh.LabelledMesh, got {type(mesh)}")
        if len(mesh.faces) == 0:
            raise ValueError("cannot cast rays at a mesh without faces")
        try:
            from embreex import rtcore_scene
            from embreex.mesh_construction import TriangleMesh
        except ImportError as exc:
            raise ValueError(
                "ray casting needs Intel Embree through the embreex package: pip install embreex"
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

    @classmethod
    def from_triangles(cls, vertices_m: np.ndarray, faces: np.ndarray) -> Raycaster:
        """A ray caster over an unlabelled mesh: ``vertices_m`` (V, 3) float, ``faces`` (F, 3)."""
        f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
        zeros = np.zeros(len(f), dtype=np.int64)
        return cls(LabelledMesh(vertices_m, f, zeros, zeros))

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

    def open_to_sky(self, points_m: np.ndarray) -> np.ndarray:
        """(N,) bool: does a vertical ray up from each point (N, 3) leave the mesh without a hit?"""
        p = np.asarray(points_m, dtype=np.float64).reshape(-1, 3)
        return ~self.occluded(p, np.broadcast_to(np.array([0.0, 0.0, 1.0]), p.shape))

    def winding_numbers(self, points_m: np.ndarray) -> np.ndarray:
        """(N,) float64 generalised winding number of the mesh at each point (N, 3).

        See :func:`winding_numbers`.
        """
        return winding_numbers(self.mesh.triangles_m - self._shift_m,
                               np.asarray(points_m, dtype=np.float64) - self._shift_m)

    def contains(self, points_m: np.ndarray) -> np.ndarray:
        """(N,) bool: points (N, 3) inside the building (winding number >= 1/2).

        Inside is the union of the mesh's closed bodies, overlapping or not; a point on
        a face is undecided (either answer, the same on every run).
        """
        return self.winding_numbers(points_m) >= INSIDE_WINDING

    def _to_embree(self, origins_m: np.ndarray) -> np.ndarray:
        return (origins_m - self._shift_m).astype(np.float32)


def winding_numbers(triangles_m: np.ndarray, points_m: np.ndarray) -> np.ndarray:
    """Generalised winding number of a triangle soup at points (Jacobson et al. 2013).

    The sum of the signed solid angles of the triangles seen from each point
    (Van Oosterom and Strackee's formula), divided by 4 pi: 1 inside a closed
    outward-oriented body, 0 outside it, k inside k overlapping bodies; a hole or
    crack only changes it near the gap.

    Parameters
    ----------
    triangles_m : (F, 3, 3) float
    points_m : (N, 3) float

    Returns
    -------
    (N,) float64. Each point's sum runs over all faces at once, so the result does not
    depend on how many points are asked together.
    """
    tri = np.asarray(triangles_m, dtype=np.float64).reshape(-1, 3, 3)
    p = np.asarray(points_m, dtype=np.float64).reshape(-1, 3)
    out = np.zeros(len(p))
    if len(tri) == 0:
        return out
    step = max(1, WINDING_BATCH_ELEMENTS // len(tri))
    for lo in range(0, len(p), step):
        rel = tri[None, :, :, :] - p[lo:lo + step, None, None, :]  # (n, F, 3, 3)
        a, b, c = rel[:, :, 0], rel[:, :, 1], rel[:, :, 2]
        la, lb, lc = (np.linalg.norm(x, axis=-1) for x in (a, b, c))
        det = np.einsum("nfi,nfi->nf", a, np.cross(b, c))
        den = (la * lb * lc + np.einsum("nfi,nfi->nf", a, b) * lc
               + np.einsum("nfi,nfi->nf", a, c) * lb + np.einsum("nfi,nfi->nf", b, c) * la)
        out[lo:lo + step] = np.sum(np.arctan2(det, den), axis=1) / (2.0 * np.pi)
    return out


def _check_rays(origins_m: np.ndarray, dirs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    o = np.asarray(origins_m, dtype=np.float64)
    d = np.asarray(dirs, dtype=np.float64)
    if o.ndim != 2 or o.shape[1] != 3 or o.shape != d.shape:
        raise ValueError(
            f"ray origins and directions must both be (N, 3), got {o.shape} and {d.shape}"
        )
    return o, d
