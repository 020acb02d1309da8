"""Facade planes of a semantic mesh, and each triangle's shadow on them (the plane projection).

Geometry helpers shared with :mod:`neural3d.extraction.facade_groups` (azimuths, circular
means) live here too, so that the dependency runs one way: facade_groups -> facade_planes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from envelope.mesh import triangle_normals
from neural3d.extraction.measure_config import MeasureConfig


@dataclass(frozen=True)
class FacadePlanes:
    """Facade planes of a mesh and the share of each triangle's area that counts on each.

    ``azimuth_deg`` (K,) and ``offset_m`` (K,): plane k is {x : x.N_k = offset_m[k]}
    with N_k the horizontal unit normal at ``azimuth_deg[k]``, in increasing
    azimuth, offset, then position along it. ``extent_m`` (K, 2): the stretch
    [start, end] of plane k along its tangent (:func:`plane_frame`) that counts
    triangles: its group's triangles' extent widened by ``plane_slab_m`` each way.
    ``weight`` (F, K): the share of triangle f's area that
    counts on plane k (n.N_k, its shadow on the plane, divided by the cosine of
    its strip, see ``_strip_cosine``, unless it is a corner counted on two
    planes), else 0. ``residual`` (F,): 1 for facade triangles near no plane
    within ``facade_max_tilt_deg`` of vertical (counted with their full area),
    else 0.
    """

    azimuth_deg: np.ndarray
    offset_m: np.ndarray
    weight: np.ndarray
    residual: np.ndarray
    extent_m: np.ndarray


def project_onto_facade_planes(
    vertices_m: np.ndarray,
    faces: np.ndarray,
    facade_area_m2: np.ndarray,
    group: np.ndarray,
    *,
    config: MeasureConfig,
) -> FacadePlanes:
    """Facade planes of a semantic mesh and the projected share of every triangle on them.

    The facade groups propose planes, each bounded along its tangent by its group's
    extent widened by ``plane_slab_m``; planes are taken greedily, most unclaimed
    projected facade area first, each claiming the unclaimed triangles near it
    (``plane_slab_m``), within its extent, that face it (within
    ``plane_max_angle_deg``) and that no parallel proposal (azimuths less than half
    ``min_facade_separation_deg`` apart) holds nearer (a bay's front and the wall
    behind it, or a window recessed in either, each count on their own); proposals
    left with less than the groups' minimum area are dropped. A triangle counts
    on the plane that claimed it and also on any other taken plane it is near
    and faces whose normal is at least ``plane_max_angle_deg`` away: the cut
    corner between two walls (a marching-cubes chamfer) then projects onto both,
    while the overlapping segments of one curved wall count it once.

    Parameters
    ----------
    vertices_m : (V, 3) float64, world metres; faces : (F, 3) int64, outward
    facade_area_m2 : (F,) wall + window + door share of each triangle's area
        (``neural3d.extraction.facade_groups.class_area_m2``)
    group : (F,) facade group (-1 none) from
        ``neural3d.extraction.facade_groups.group_facade_faces``
    config : ``neural3d.extraction.measure_config.MeasureConfig``
    """
    normal = triangle_normals(vertices_m[faces])
    centroid_xy = vertices_m[faces].mean(axis=1)[:, :2]
    idx = np.flatnonzero(facade_area_m2 > 0)
    taken: list[int] = []
    weight_i = np.zeros((len(idx), 0))
    az_off: list[tuple[float, float]] = []
    if group.max() >= 0 and len(idx):
        az_off = [azimuth_offset(normal[group == k], centroid_xy[group == k],
                                   facade_area_m2[group == k]) for k in range(group.max() + 1)]
        az = np.radians([a for a, _ in az_off])
        plane_n = np.stack([np.cos(az), np.sin(az)], axis=1)  # (K, 2)
        plane_t = np.stack([-plane_n[:, 1], plane_n[:, 0]], axis=1)  # (K, 2) tangents
        corners_xy = vertices_m[faces][:, :, :2]  # (F, 3, 2)
        extents = np.array([[(corners_xy[group == k] @ plane_t[k]).min() - config.plane_slab_m,
                             (corners_xy[group == k] @ plane_t[k]).max() + config.plane_slab_m]
                            for k in range(len(az_off))])  # (K, 2)
        facing = normal[idx, :2] @ plane_n.T  # (I, K) n.N
        near = np.abs(centroid_xy[idx] @ plane_n.T - np.array([d for _, d in az_off]))
        along = centroid_xy[idx] @ plane_t.T  # (I, K)
        cos_max = np.cos(np.radians(config.plane_max_angle_deg))
        inlier = ((near <= config.plane_slab_m) & (facing >= cos_max)
                  & (along >= extents[:, 0]) & (along <= extents[:, 1]))
        parallel = np.abs(wrap_deg(np.degrees(az)[:, None] - np.degrees(az)[None, :])
                          ) < config.min_facade_separation_deg / 2  # (K, K)
        nearest = np.where(inlier, near, np.inf)  # (I, K)
        nearest_parallel = np.stack([nearest[:, parallel[k]].min(axis=1)
                                     for k in range(len(az_off))], axis=1)
        inlier &= near <= nearest_parallel
        support = facade_area_m2[idx, None] * np.where(inlier, facing, 0.0)  # (I, K) m²
        min_area = config.min_group_area_m2(float(facade_area_m2[group >= 0].sum()))
        claimed_by = np.full(len(idx), -1)
        while True:
            totals = support[claimed_by < 0].sum(axis=0)
            totals[taken] = -1.0
            k = int(np.argmax(totals))
            if totals[k] < min_area:
                break
            claimed_by[(claimed_by < 0) & inlier[:, k]] = k
            taken.append(k)
        taken.sort(key=lambda k: (*az_off[k], float(extents[k].mean())))
        weight_i = np.zeros((len(idx), len(taken)))
        for j, k in enumerate(taken):  # corners: shadows on the other walls they face
            apart = plane_n[claimed_by] @ plane_n[k] <= cos_max + 1e-9  # (I,) other facades
            also = (claimed_by >= 0) & (claimed_by != k) & apart & inlier[:, k]
            weight_i[also, j] = facing[also, k]
        corner = weight_i.sum(axis=1) > 0
        for j, k in enumerate(taken):
            own = claimed_by == k
            weight_i[own & corner, j] = facing[own & corner, k]
            flat = np.flatnonzero(own & ~corner)  # a corner is two walls' shadows, not a curve
            weight_i[flat, j] = facing[flat, k] / _strip_cosine(
                normal[idx[flat], :2], centroid_xy[idx[flat]], facade_area_m2[idx[flat]],
                plane_n[k], config.curve_strip_m, floor=cos_max)
    extent = extents[taken] if taken else np.zeros((0, 2))
    weight = np.zeros((len(faces), len(taken)))
    weight[idx] = weight_i
    near_plane = np.zeros(len(faces), dtype=bool)
    if taken:
        within = (along[:, taken] >= extent[:, 0]) & (along[:, taken] <= extent[:, 1])
        near_plane[idx] = ((near[:, taken] <= config.plane_slab_m) & within).any(axis=1)
    horizontal = np.linalg.norm(normal[:, :2], axis=1)
    # a reveal or a recess side is near a plane it does not face: its shadow is 0, not its area
    residual = (~near_plane & (facade_area_m2 > 0)
                & (horizontal >= np.cos(np.radians(config.facade_max_tilt_deg)))).astype(float)
    return FacadePlanes(
        azimuth_deg=np.array([az_off[k][0] for k in taken]),
        offset_m=np.array([az_off[k][1] for k in taken]),
        weight=weight, residual=residual, extent_m=extent,
    )


def _strip_cosine(normal_xy: np.ndarray, centroid_xy: np.ndarray, weight: np.ndarray,
                  plane_normal_xy: np.ndarray, strip_m: float, *, floor: float) -> np.ndarray:
    """(I,) cosine between the plane's normal and the mean normal of each triangle's strip.

    The triangles are cut into vertical strips ``strip_m`` wide along the plane;
    dividing a triangle's projected area by this cosine projects it onto its
    strip's own mean plane instead: the same for a flat wall (cosine 1), the
    true area for a wall curving away from the plane, still the shadow for a
    recess or a ripple narrower than a strip. Clamped below at ``floor``.
    """
    tangent = np.array([-plane_normal_xy[1], plane_normal_xy[0]])
    strip = np.floor(centroid_xy @ tangent / strip_m).astype(np.int64)
    strip -= strip.min(initial=0)
    mean = np.stack([np.bincount(strip, weights=weight * normal_xy[:, i]) for i in (0, 1)], 1)
    length = np.linalg.norm(mean, axis=1)
    cosine = np.divide(mean @ plane_normal_xy, length, out=np.ones(len(mean)), where=length > 0)
    return np.maximum(cosine[strip], floor)


def plane_frame(azimuth_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """(normal (3,), tangent (3,)): horizontal unit vectors of a facade plane at ``azimuth_deg``
    (tangent (-N_y, N_x, 0), so u runs counter-clockwise seen from above), world frame."""
    a = np.radians(azimuth_deg)
    return np.array([np.cos(a), np.sin(a), 0.0]), np.array([-np.sin(a), np.cos(a), 0.0])


def azimuth_offset(
    normal: np.ndarray, centroid_xy: np.ndarray, weight: np.ndarray
) -> tuple[float, float]:
    """Weighted mean azimuth (deg) of faces and their mean offset (m) along it."""
    az = circular_mean_deg(np.degrees(np.arctan2(normal[:, 1], normal[:, 0])), weight)
    u = np.array([np.cos(np.radians(az)), np.sin(np.radians(az))])
    return az, float(np.average(centroid_xy @ u, weights=weight))


def circular_mean_deg(angle_deg: np.ndarray, weight: np.ndarray) -> float:
    """Weighted circular mean of (N,) angles in degrees, in [0, 360)."""
    r = np.radians(angle_deg)
    return float(np.degrees(np.arctan2((weight * np.sin(r)).sum(),
                                       (weight * np.cos(r)).sum())) % 360.0)


def wrap_deg(delta_deg: np.ndarray) -> np.ndarray:
    """Angle differences wrapped into [-180, 180)."""
    return (delta_deg + 180.0) % 360.0 - 180.0
