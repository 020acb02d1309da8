"""dataset.importers.mesh.crossings: faces cut along the lines where other faces pass through."""

import numpy as np
import pytest
import trimesh

from dataset.importers.mesh.crossings import split_crossing_faces
from envelope.classes import SemanticClass
from envelope.mesh import LabelledMesh


def _mesh(*boxes) -> LabelledMesh:
    both = trimesh.util.concatenate([trimesh.creation.box(bounds=np.array(b, float))
                                     for b in boxes])
    n = len(both.faces)
    return LabelledMesh(both.vertices, both.faces, np.full(n, SemanticClass.WALL),
                        np.zeros(n, dtype=np.int32))


def test_a_face_passing_into_another_box_is_cut_where_it_enters():
    # A = [0, 10] x [0, 8] x [0, 6], B = [4, 12] x [4, 10] x [0, 6]: A's east face (x = 10)
    # is cut at y = 4, its north face (y = 8) at x = 4; area and orientation are kept.
    mesh = _mesh(((0, 0, 0), (10, 8, 6)), ((4, 4, 0), (12, 10, 6)))
    upright = np.abs(mesh.face_normals()[:, 2]) < 0.5
    out, parent = split_crossing_faces(mesh, upright)
    assert out.face_areas_m2().sum() == pytest.approx(mesh.face_areas_m2().sum(), rel=1e-12)
    np.testing.assert_allclose(out.face_normals(), mesh.face_normals()[parent], atol=1e-9)
    east = (np.abs(out.face_normals()[:, 0] - 1) < 1e-9) & (
        np.abs(out.triangles_m[:, :, 0] - 10).max(axis=1) < 1e-9)
    y = out.triangles_m[east][:, :, 1]
    assert ((y.max(axis=1) <= 4 + 1e-9) | (y.min(axis=1) >= 4 - 1e-9)).all()
    assert out.face_areas_m2()[east][y.mean(axis=1) < 4].sum() == pytest.approx(24.0)


def test_touching_and_separate_boxes_are_not_cut():
    mesh = _mesh(((0, 0, 0), (1, 1, 1)), ((1, 0, 0), (2, 1, 1)), ((5, 5, 5), (6, 6, 6)))
    out, parent = split_crossing_faces(mesh, np.ones(len(mesh.faces), dtype=bool))
    assert out is mesh and (parent == np.arange(len(mesh.faces))).all()
