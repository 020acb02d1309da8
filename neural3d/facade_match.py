"""Give a semantic mesh's facade groups the truth's facade ids, so per-facade errors can be taken.

This is evaluation bookkeeping, not part of the estimate: the figures of every
group come from :func:`neural3d.measure.measure_semantic_mesh` unchanged; only
their ids (and the merging of several groups that face one truth facade, such
as the segments of a curved wall) come from the truth mesh.

Each group goes, whole, to the truth facade that most of its area lies next
to: its triangles' centroids vote for the facade id of the nearest point
sampled every ``spacing_m`` on the truth's facade faces, weighted by the
triangle's facade-class area, counting only votes where the two normals agree
within 45 degrees.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.spatial import cKDTree

from dataset.classes import FACADE_CLASSES
from dataset.mesh import LabelledMesh, triangle_areas_m2
from metrics.wwr import gross_facade_area_m2, window_to_wall_ratio
from neural3d.measure import (
    MeasureConfig,
    MeshFacade,
    MeshMeasurement,
    class_area_m2,
    group_facade_faces,
)

MAX_NORMAL_ANGLE_DEG = 45.0  # a vote counts only if mesh and truth normals agree this well


def facades_by_truth(
    vertices_m: np.ndarray,
    faces: np.ndarray,
    vertex_labels: np.ndarray,
    measurement: MeshMeasurement,
    truth_mesh: LabelledMesh,
    *,
    config: MeasureConfig | None = None,
    spacing_m: float = 0.2,
) -> tuple[dict[int, MeshFacade], tuple[int, ...]]:
    """Per-facade figures of ``measurement`` under the truth's facade ids.

    Parameters
    ----------
    vertices_m, faces, vertex_labels
        The semantic mesh ``measurement`` was taken from, with the same ``config``
        (None: the default :class:`MeasureConfig`).
    truth_mesh : LabelledMesh
        Ground-truth mesh with per-face facade ids (``<scene>/mesh.ply``).

    Returns
    -------
    facades : {truth facade id: MeshFacade with ``index`` = that id}; merged
        groups add areas and widths and keep the largest height.
    unmatched : indices of the groups that no truth facade took.
    """
    if spacing_m <= 0:
        raise ValueError(f"spacing_m must be > 0, got {spacing_m}")
    vertices_m = np.asarray(vertices_m, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    group = group_facade_faces(vertices_m, faces, vertex_labels, config=config or MeasureConfig())
    n_groups = len(measurement.facades)
    if int(group.max(initial=-1)) + 1 != n_groups:
        raise ValueError("measurement does not belong to this mesh and config; measure it again")
    points, normals, ids = _sample_truth_facades(truth_mesh, spacing_m)
    owner = np.full(n_groups, -1)
    member = np.flatnonzero(group >= 0)
    if len(ids) and len(member):
        tri = vertices_m[faces[member]]
        _, nearest = cKDTree(points).query(tri.mean(axis=1))
        agree = (np.sum(_unit_normals(tri) * normals[nearest], axis=1)
                 > np.cos(np.radians(MAX_NORMAL_ANGLE_DEG)))
        weight = class_area_m2(vertices_m, faces[member], vertex_labels)[:, list(FACADE_CLASSES)]
        votes = np.zeros((n_groups, int(ids.max()) + 1))
        np.add.at(votes, (group[member][agree], ids[nearest][agree]), weight.sum(axis=1)[agree])
        owner = np.where(votes.max(axis=1) > 0, votes.argmax(axis=1), -1)
    matched = {
        int(fid): _merge([measurement.facades[i] for i in np.flatnonzero(owner == fid)], int(fid))
        for fid in sorted(set(owner.tolist()) - {-1})
    }
    return matched, tuple(int(i) for i in np.flatnonzero(owner < 0))


def _sample_truth_facades(
    truth_mesh: LabelledMesh, spacing_m: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points ~``spacing_m`` apart on the truth's facade faces, their normals and facade ids."""
    keep = truth_mesh.face_facade > 0
    tri = truth_mesh.triangles_m[keep]
    if len(tri) == 0:
        return np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0, dtype=np.int64)
    counts = np.maximum(1, np.ceil(triangle_areas_m2(tri) / spacing_m**2)).astype(int)
    face = np.repeat(np.arange(len(tri)), counts)
    rng = np.random.default_rng(0)  # fixed: the same truth always gives the same samples
    r1, r2 = rng.random(len(face)), rng.random(len(face))
    flip = r1 + r2 > 1  # fold the square onto the triangle: uniform barycentric samples
    r1[flip], r2[flip] = 1 - r1[flip], 1 - r2[flip]
    t = tri[face]
    points = t[:, 0] + r1[:, None] * (t[:, 1] - t[:, 0]) + r2[:, None] * (t[:, 2] - t[:, 0])
    return points, _unit_normals(tri)[face], truth_mesh.face_facade[keep][face].astype(np.int64)


def _merge(parts: list[MeshFacade], index: int) -> MeshFacade:
    if len(parts) == 1:
        return replace(parts[0], index=index)
    area = np.array([p.facade_area_m2 for p in parts])
    normal = np.average([p.normal for p in parts], axis=0, weights=area)
    normal /= max(float(np.linalg.norm(normal)), 1e-12)
    window, wall, door = (sum(getattr(p, k) for p in parts)
                          for k in ("window_area_m2", "wall_area_m2", "door_area_m2"))
    gross = gross_facade_area_m2(wall, window, door)
    return MeshFacade(
        index=index,
        normal=tuple(round(float(c), 12) + 0.0 for c in normal),
        azimuth_deg=float(np.degrees(np.arctan2(normal[1], normal[0])) % 360.0),
        offset_m=float(np.average([p.offset_m for p in parts], weights=area)),
        window_area_m2=window,
        wall_area_m2=wall,
        door_area_m2=door,
        facade_area_m2=gross,
        wwr=window_to_wall_ratio(window, gross) if gross > 0 else None,
        width_m=sum(p.width_m for p in parts),
        height_m=max(p.height_m for p in parts),
        face_count=sum(p.face_count for p in parts),
    )


def _unit_normals(triangles_m: np.ndarray) -> np.ndarray:
    n = np.cross(triangles_m[:, 1] - triangles_m[:, 0], triangles_m[:, 2] - triangles_m[:, 0])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return np.divide(n, length, out=np.zeros_like(n), where=length > 0)
