"""dataset.importers.mesh.mesh_files: class names, vertex merging, OBJ parsing."""

import numpy as np
import pytest

from dataset.importers.mesh.mesh_files import (
    class_from_name,
    merge_vertices,
    read_labelled_mesh_file,
)
from envelope.classes import SemanticClass


@pytest.mark.parametrize("name, expected", [
    ("Wall", SemanticClass.WALL),
    ("  WINDOW ", SemanticClass.WINDOW),
    ("Wall.001", SemanticClass.WALL),
    ("window_3", SemanticClass.WINDOW),
    ("Door-12", SemanticClass.DOOR),
    ("Wall_North", SemanticClass.WALL),
    ("glazing", SemanticClass.WINDOW),
    ("Roofs", SemanticClass.ROOF),
    ("other", SemanticClass.OTHER),
    ("Balustrade", None),
    ("Cube.001", None),
    ("", None),
])
def test_class_from_name(name, expected):
    assert class_from_name(name) == expected


def test_merge_vertices_keeps_face_order_and_joins_negative_zero():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [-0.0, 0, 0], [1, 1e-12, 0], [1, 1, 0]])
    f = np.array([[0, 1, 2], [3, 4, 5]])
    mv, mf = merge_vertices(v, f)
    assert len(mv) == 4
    np.testing.assert_array_equal(mv[mf], np.round(v[f], 9) + 0.0)
    assert mf[0, 0] == mf[1, 0] and mf[0, 1] == mf[1, 1]


def test_obj_quads_negative_indices_and_name_precedence(tmp_path):
    path = tmp_path / "m.obj"
    path.write_text(
        "o House\nusemtl Window\n"
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
        "vt 0 0\nvn 0 0 1\n"
        "f 1/1/1 2/1/1 3/1/1 4/1/1\n"  # quad, material names the class
        "g wall\n"
        "f -4 -2 -1\n"  # group beats material
    )
    mesh = read_labelled_mesh_file(path)
    corners = mesh.vertices_m[mesh.faces][:, :, :2]
    np.testing.assert_array_equal(
        corners, [[[0, 0], [1, 0], [1, 1]], [[0, 0], [1, 1], [0, 1]], [[0, 0], [1, 1], [0, 1]]]
    )
    np.testing.assert_array_equal(mesh.face_label, [2, 2, 1])
    assert (mesh.face_facade == 0).all()


def test_obj_parse_error_names_the_line(tmp_path):
    (tmp_path / "m.obj").write_text("o Wall\nv 0 0 0\nf 1 2 x\n")
    with pytest.raises(ValueError, match="line 3"):
        read_labelled_mesh_file(tmp_path / "m.obj")
    (tmp_path / "n.obj").write_text("o Wall\nv 0 0 0\nf 1 2 3\n")
    with pytest.raises(ValueError, match="vertex that does not exist"):
        read_labelled_mesh_file(tmp_path / "n.obj")


def test_y_up_rotates_to_z_up(tmp_path):
    (tmp_path / "m.obj").write_text("o Wall\nv 0 0 0\nv 1 0 0\nv 0 2 0\nf 1 2 3\n")
    mesh = read_labelled_mesh_file(tmp_path / "m.obj", up_axis="y")
    np.testing.assert_allclose(mesh.vertices_m[mesh.faces[0]], [[0, 0, 0], [1, 0, 0], [0, 0, 2]])
