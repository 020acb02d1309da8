"""Which faces of a building can be seen from outside, by ray casting
(:mod:`envelope.geometry.raycast`).

A face is sampled at :data:`SAMPLE_BARYCENTRIC` points, each nudged ``offset_m`` off the
surface along the face normal; from each sample, rays leave along a fixed set of
directions spread over the outward hemisphere. The fraction of rays that hit nothing
is the face's escape fraction: 0 for faces enclosed by the mesh (inner sides of walls,
partitions, ceilings of a BIM export), and typically >= 0.3 for an outside wall. With a
ground height, every ray that points downwards counts as stopped by the ground, so an
open underside (no floor slab, a crawl space) does not let the inner sides of the walls
see out; an outside wall then keeps about half its rays. With a ground box, the ground is
the plane z = 0 within that x/y box only: a downward ray that leaves the box before it
reaches z = 0 escapes, as a camera on the ground beyond the box would see along it
(the wall under an eave, which the eave hides from every upward ray).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from tqdm import tqdm

from envelope.mesh import plane_bases

if TYPE_CHECKING:
    from envelope.geometry.raycast import Raycaster

SAMPLE_BARYCENTRIC = np.array(
    [[1 / 3, 1 / 3, 1 / 3], [0.6, 0.2, 0.2], [0.2, 0.6, 0.2], [0.2, 0.2, 0.6]]
)
"""(S, 3) barycentric sample points: centroid and three points towards the corners.

They keep 0.2 of the way from every edge, so that a ray from a face in an inside corner
starts clear of the neighbouring face.
"""
MIN_ESCAPE_FRACTION = 0.02
"""A face is seen from outside when at least this fraction of its rays escape (one in 50)."""
RAY_OFFSET_M = 1e-3
"""Rays start this far off the surface (embree works in float32)."""
MIN_RAY_COSINE = 0.1  # no ray within ~6 deg of the face plane: it would graze coplanar neighbours
RAYS_PER_BATCH = 1 << 20  # bounds memory: ~100 MB of float64 per batch


def hemisphere_directions(count: int) -> np.ndarray:
    """(count, 3) float64 unit directions over the +z hemisphere (z >= :data:`MIN_RAY_COSINE`).

    A Fibonacci spiral, even in solid angle, deterministic.
    """
    if count < 1:
        raise ValueError(f"need at least one ray direction, got {count}")
    i = np.arange(count, dtype=np.float64) + 0.5
    z = 1.0 - i / count * (1.0 - MIN_RAY_COSINE)
    azimuth = i * np.pi * (3.0 - np.sqrt(5.0))
    r = np.sqrt(1.0 - z * z)
    return np.stack([r * np.cos(azimuth), r * np.sin(azimuth), z], axis=1)


def escape_fractions(
    raycaster: Raycaster,
    triangles_m: np.ndarray,
    normals: np.ndarray,
    *,
    rays_per_sample: int,
    offset_m: float,
    ground: bool = False,
    ground_box_xy_m: np.ndarray | None = None,
    show_progress: bool = True,
) -> np.ndarray:
    """Fraction of outward rays from each face that leave the mesh without a hit.

    Parameters
    ----------
    raycaster
        :class:`envelope.geometry.raycast.Raycaster` over the whole mesh.
    triangles_m : (F, 3, 3) float
        The faces to test (any subset of the mesh).
    normals : (F, 3) float
        Their outward unit normals; a zero normal (degenerate face) gives fraction 0.
    rays_per_sample
        Directions per sample point (:func:`hemisphere_directions`).
    offset_m
        How far off the surface the rays start, above embree's float32 precision.
    ground
        Whether the faces stand above a ground: rays pointing downwards never escape.
    ground_box_xy_m : (2, 2) float, optional
        With ``ground``: ((x_min, y_min), (x_max, y_max)), world metres. The ground is then
        the plane z = 0 within this box: a downward ray stops only where it meets z = 0
        inside it (or starts below z = 0). None: every downward ray stops.

    Returns
    -------
    (F,) float64 in [0, 1].
    """
    tri = np.asarray(triangles_m, dtype=np.float64)
    n = np.asarray(normals, dtype=np.float64)
    if tri.ndim != 3 or tri.shape[1:] != (3, 3) or n.shape != (len(tri), 3):
        raise ValueError(f"need triangles (F, 3, 3) and normals (F, 3), got {tri.shape}, {n.shape}")
    result = np.zeros(len(tri))
    valid = np.linalg.norm(n, axis=1) > 0.5
    if not valid.any():
        return result
    local = hemisphere_directions(rays_per_sample)
    starts = np.einsum("sk,fkd->fsd", SAMPLE_BARYCENTRIC, tri[valid])  # (F, S, 3)
    starts += offset_m * n[valid, None, :]
    dirs = _to_world(local, n[valid])  # (F, K, 3)
    n_faces = len(starts)
    rays_per_face = starts.shape[1] * len(local)
    faces_per_batch = max(1, RAYS_PER_BATCH // rays_per_face)
    escaped = np.zeros(n_faces)
    batches = range(0, n_faces, faces_per_batch)
    for lo in tqdm(batches, desc="visibility", unit="batch",
                   disable=not show_progress or len(batches) < 4):
        hi = min(lo + faces_per_batch, n_faces)
        o = np.broadcast_to(starts[lo:hi, :, None, :], (hi - lo, starts.shape[1], len(local), 3))
        d = np.broadcast_to(dirs[lo:hi, None, :, :], o.shape)
        d = d.reshape(-1, 3)
        hit = raycaster.occluded(o.reshape(-1, 3), d)
        if ground:
            hit |= _stopped_by_ground(o.reshape(-1, 3), d, ground_box_xy_m)
        escaped[lo:hi] = 1.0 - hit.reshape(hi - lo, -1).mean(axis=1)
    result[valid] = escaped
    return result


def seen_from_outside(
    raycaster: Raycaster,
    which: np.ndarray,
    *,
    rays_per_sample: int,
    offset_m: float,
    min_escape_fraction: float,
    ground: bool = True,
    ground_box_xy_m: np.ndarray | None = None,
    show_progress: bool = False,
) -> np.ndarray:
    """(F,) bool over the raycaster's mesh: faces in ``which`` ((F,) bool) whose escape
    fraction (:func:`escape_fractions`) is at least ``min_escape_fraction``; False elsewhere."""
    mesh = raycaster.mesh
    seen = np.zeros(len(mesh.faces), dtype=bool)
    if which.any():
        seen[which] = escape_fractions(
            raycaster, mesh.triangles_m[which], raycaster.face_normals[which],
            rays_per_sample=rays_per_sample, offset_m=offset_m, ground=ground,
            ground_box_xy_m=ground_box_xy_m, show_progress=show_progress,
        ) >= min_escape_fraction
    return seen


def _stopped_by_ground(origins_m: np.ndarray, dirs: np.ndarray,
                       box_xy_m: np.ndarray | None) -> np.ndarray:
    """(N,) bool: rays (N, 3) pointing downwards that meet the ground: every one without a
    box; with a (2, 2) x/y box, those that start below z = 0 or meet z = 0 inside it."""
    down = dirs[:, 2] < 0
    if box_xy_m is None:
        return down
    lo, hi = np.asarray(box_xy_m, dtype=np.float64)
    t = np.divide(-origins_m[:, 2], dirs[:, 2], out=np.zeros(len(dirs)), where=down)
    xy = origins_m[:, :2] + t[:, None] * dirs[:, :2]
    inside = ((xy >= lo) & (xy <= hi)).all(axis=1)
    return down & ((origins_m[:, 2] <= 0) | inside)


def _to_world(local: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """(F, K, 3) directions: ``local`` (K, 3) hemisphere about +z turned about each normal."""
    u, v = plane_bases(normals)
    return (
        local[None, :, 0:1] * u[:, None, :]
        + local[None, :, 1:2] * v[:, None, :]
        + local[None, :, 2:3] * normals[:, None, :]
    )
