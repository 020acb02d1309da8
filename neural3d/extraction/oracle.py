"""A labelled truth mesh as a perfect field: what neural3d's extraction would meet if training
were exact.

:class:`OracleField` answers like :class:`neural3d.field.trained.TrainedField` (world metres,
CPU tensors):

- **signed distance**: the distance to the nearest of the triangles under the
  :data:`CANDIDATE_FACES` surface samples nearest the point (random samples about a
  third of a voxel apart: exact but at a few points near edges, where it may be
  up to that spacing long), within :data:`BAND_VOXELS` voxels of the surface,
  clipped to that beyond (marching cubes reads only the cells the surface crosses); inside
  is the union of the mesh's closed bodies (ray parity per body: a chimney
  through a roof stays inside, as with the project's winding-number rule,
  :mod:`envelope.geometry.raycast`);
- **class probabilities**: one-hot of the label of the nearest truth face (that
  of the nearest surface sample);
- **colour**: mid grey (the measurement reads none).

:func:`scene_box_m` gives the box a trained field of the building would have. The extraction
runs unchanged on the field (``bench/oracle_measure.py`` measures each stage this way; the
tests of the concave-corner stage mesh a sharp corner from it).
"""

from __future__ import annotations

import hashlib

import numpy as np
import torch
import trimesh
from scipy.spatial import cKDTree

from envelope.classes import CLASS_NAMES, NUM_CLASSES
from envelope.mesh import LabelledMesh, triangle_areas_m2
from envelope.protocols import TRAIN_PROTOCOL

CANDIDATE_FACES = 8  # nearest surface samples whose triangles are tested exactly
SAMPLES_PER_VOXEL = 3  # surface samples per voxel length
BAND_VOXELS = 2  # the distance is exact this many voxels from the surface, clipped beyond
OFF_LOGIT = -1.0e4  # logit of every class but the nearest face's: softmax gives exactly 0
MEMO_ENTRIES = 32  # SDF answers kept: the footprint asks the same planes for every stage set


class OracleField:
    """A labelled truth mesh behind the interface of :class:`neural3d.field.trained.TrainedField`
    (world metres, CPU tensors): exact signed distance near the surface, one-hot classes of
    the nearest face, grey colour (this module's docstring).

    Parameters
    ----------
    mesh : the truth mesh, a union of closed bodies (each watertight)
    name : the building's id (``scene_name`` of its results)
    voxel_m : the marching-cubes voxel the field will be meshed at: it sets the surface
        samples' spacing (a third of it) and the exact band (:data:`BAND_VOXELS` of it)
    box_min_m, box_max_m : (3,) the box the field is meshed and outlined in

    Raises
    ------
    ValueError
        If a body of the mesh is not closed (ray parity needs closed bodies).
    """

    class_names = CLASS_NAMES
    device = torch.device("cpu")
    split = TRAIN_PROTOCOL  # its results stand in for a field trained on the orbit

    def __init__(self, mesh: LabelledMesh, name: str, *, voxel_m: float,
                 box_min_m: np.ndarray, box_max_m: np.ndarray):
        self.mesh = mesh
        self.scene_name = name
        self.box_min_m = np.asarray(box_min_m, dtype=np.float64)
        self.box_max_m = np.asarray(box_max_m, dtype=np.float64)
        self.band_m = BAND_VOXELS * voxel_m
        self.bodies = trimesh.Trimesh(mesh.vertices_m, mesh.faces).split(only_watertight=False,
                                                                          repair=False)
        if not all(body.is_watertight for body in self.bodies):
            raise ValueError(f"{name}: a body of the truth mesh is not closed; the oracle's "
                             "inside test (ray parity per body) needs closed bodies")
        tri = mesh.triangles_m
        spacing_m = voxel_m / SAMPLES_PER_VOXEL
        counts = np.maximum(1, np.ceil(triangle_areas_m2(tri) / spacing_m**2)).astype(int)
        self.sample_face = np.repeat(np.arange(len(tri)), counts)
        r = np.random.default_rng(0).random((len(self.sample_face), 2))
        r[r.sum(1) > 1] = 1 - r[r.sum(1) > 1]
        t = tri[self.sample_face]
        self.tree = cKDTree(t[:, 0] + r[:, :1] * (t[:, 1] - t[:, 0])
                            + r[:, 1:] * (t[:, 2] - t[:, 0]))
        self._memo: dict[bytes, np.ndarray] = {}

    def sdf(self, points_m: np.ndarray) -> np.ndarray:
        """(N, 3) world m -> (N,) signed distance in m, positive outside, clipped at the band."""
        key = hashlib.sha1(np.ascontiguousarray(points_m).tobytes()).digest()
        if key not in self._memo:
            if len(self._memo) >= MEMO_ENTRIES:
                self._memo.pop(next(iter(self._memo)))
            self._memo[key] = self._sdf(points_m)
        return self._memo[key]

    def _sdf(self, points_m: np.ndarray) -> np.ndarray:
        d, _ = self.tree.query(points_m, distance_upper_bound=self.band_m)
        d = np.minimum(d, self.band_m)
        near = np.flatnonzero(d < self.band_m)
        if len(near):
            _, idx = self.tree.query(points_m[near], k=CANDIDATE_FACES)
            faces = self.sample_face[idx].ravel()
            p = np.repeat(points_m[near], CANDIDATE_FACES, axis=0)
            closest = trimesh.triangles.closest_point(self.mesh.triangles_m[faces], p)
            d[near] = np.linalg.norm(closest - p, axis=1).reshape(-1, CANDIDATE_FACES).min(1)
        return np.where(self.contains(points_m), -d, d)

    def contains(self, points_m: np.ndarray) -> np.ndarray:
        """(N,) bool: inside one of the mesh's closed bodies (ray parity per body)."""
        inside = np.zeros(len(points_m), dtype=bool)
        for body in self.bodies:
            lo, hi = body.bounds
            box = np.flatnonzero(((points_m >= lo) & (points_m <= hi)).all(axis=1) & ~inside)
            if len(box):
                inside[box] = body.contains(points_m[box])
        return inside

    def labels(self, points_m: np.ndarray) -> np.ndarray:
        """(N, 3) world m -> (N,) class id of the nearest truth face."""
        _, idx = self.tree.query(points_m)
        return self.mesh.face_label[self.sample_face[idx]].astype(np.int64)

    def sdf_m(self, points_world_m: torch.Tensor, *, chunk_points: int = 0) -> torch.Tensor:
        """``TrainedField.sdf_m``: (N, 3) world points -> (N,) signed distance (m)."""
        return torch.from_numpy(self.sdf(points_world_m.double().numpy()))

    def semantic_logits(self, points_world_m: torch.Tensor, *,
                        chunk_points: int = 0) -> torch.Tensor:
        """``TrainedField.semantic_logits``: (N, C) logits whose softmax is exactly one-hot."""
        label = torch.from_numpy(self.labels(points_world_m.double().numpy()))
        logits = torch.full((len(label), NUM_CLASSES), OFF_LOGIT)
        logits[torch.arange(len(label)), label] = 0.0
        return logits

    def rgb(self, points_world_m: torch.Tensor, view_dirs_world: torch.Tensor, *,
            chunk_points: int = 0) -> torch.Tensor:
        """``TrainedField.rgb``: mid grey (the measurement reads no colour)."""
        return torch.full((len(points_world_m), 3), 0.5)


def scene_box_m(mesh: LabelledMesh, margin: float) -> tuple[np.ndarray, np.ndarray]:
    """A trained field's box for ``mesh``: its bounding box above z = 0 widened on each side
    by ``margin`` of its longest side (:func:`neural3d.training.scene_box.visual_hull_box_m`
    on a hull that is the building's box)."""
    lo, hi = mesh.vertices_m.min(axis=0), mesh.vertices_m.max(axis=0)
    lo[2] = max(lo[2], 0.0)
    extra = margin * float(np.max(hi - lo))
    return lo - extra, hi + extra
