"""dataset.importers.mesh.grade and dataset.importers.mesh.contact: cutting faces at the ground and
where
bodies touch."""

import numpy as np
import pytest
import trimesh

from dataset.importers.mesh.bodies import orient_bodies
from dataset.importers.mesh.contact import split_touching_faces
from dataset.importers.mesh.grade import split_at_height
from envelope.classes import SemanticClass
from envelope.mesh import LabelledMesh


def _boxes(*bounds) -> LabelledMesh:
    mesh = trimesh.util.concatenate(
        [trimesh.creation.box(bounds=np.array(b, dtype=float)) for b in bounds])
    n = len(mesh.faces)
    return LabelledMesh(mesh.vertices, mesh.faces, np.full(n, SemanticClass.WALL),
                        np.zeros(n, dtype=np.int32))


def test_split_at_height_keeps_area_orientation_and_closedness():
    box = _boxes(((0, 0, -1), (2, 3, 2)))
    cut, parent = split_at_height(box, 0.0)
    assert cut.face_areas_m2().sum() == pytest.approx(box.face_areas_m2().sum(), rel=1e-12)
    z = cut.triangles_m[:, :, 2]
    assert ((z.min(axis=1) >= -1e-12) | (z.max(axis=1) <= 1e-12)).all()  # none crosses
    np.testing.assert_allclose(cut.face_normals(), box.face_normals()[parent], atol=1e-12)
    counts = orient_bodies(cut.vertices_m, cut.faces).counts
    assert (counts["open"], counts["rewound"], counts["turned_inside_out"]) == (0, 0, 0)
    below = z.mean(axis=1) < 0
    assert cut.face_areas_m2()[below].sum() == pytest.approx(2 * 3 + 2 * (2 + 3) * 1.0)


def test_touching_faces_are_cut_along_the_cover():
    # A 1 m wide wall butts into the side of a 4 m long one over 1 m x 3 m.
    mesh = _boxes(((0, 0, 0), (4, 0.3, 3)), ((1, 0.3, 0), (2, 1.3, 3)))
    cut, parent, twin = split_touching_faces(mesh, np.ones(len(mesh.faces), dtype=bool))
    assert not twin.any()
    assert cut.face_areas_m2().sum() == pytest.approx(mesh.face_areas_m2().sum(), rel=1e-12)
    np.testing.assert_allclose(cut.face_normals(), mesh.face_normals()[parent], atol=1e-12)
    # The long wall's +y face (4 x 3) is now pieces: 3 m² covered by the other wall's -y face.
    back = (np.abs(cut.face_normals()[:, 1] - 1) < 1e-9) & (cut.triangles_m[:, 0, 1] == 0.3)
    centres = cut.triangles_m[back].mean(axis=1)
    covered = (centres[:, 0] > 1) & (centres[:, 0] < 2)
    assert cut.face_areas_m2()[back][covered].sum() == pytest.approx(3.0, rel=1e-9)
    assert cut.face_areas_m2()[back].sum() == pytest.approx(12.0, rel=1e-9)


def test_flush_faces_of_overlapping_solids_count_once():
    # Two walls overlapping at a corner, both flush on the outside (x = 0 and y = 0).
    mesh = _boxes(((0, 0, 0), (4, 0.3, 3)), ((0, 0, 0), (0.3, 3, 3)))
    cut, parent, twin = split_touching_faces(mesh, np.ones(len(mesh.faces), dtype=bool))
    assert cut.face_areas_m2().sum() == pytest.approx(mesh.face_areas_m2().sum(), rel=1e-12)
    # The later wall's -y end face (0.3 x 3), the 0.3 x 3 strip of its -x face, and the
    # 0.3 x 0.3 overlap of its top and of its bottom.
    assert cut.face_areas_m2()[twin].sum() == pytest.approx(2 * 0.3 * 3 + 2 * 0.09, rel=1e-9)
    assert (parent[twin] >= 12).all()  # all on the second box's faces


def test_walls_overlapping_at_every_corner_give_the_outline_once(tmp_path):
    from dataset.importers.mesh.mesh_import import import_labelled_mesh
    from envelope.mesh import write_labelled_ply

    walls = _boxes(((0, 0, 0), (10, 0.3, 3)), ((0, 7.7, 0), (10, 8, 3)),
                   ((0, 0, 0), (0.3, 8, 3)), ((9.7, 0, 0), (10, 8, 3)), ((0, 0, 3), (10, 8, 3.2)))
    label = walls.face_label.copy()
    label[-12:] = SemanticClass.ROOF  # the last box is a roof slab
    write_labelled_ply(tmp_path / "walls.ply", LabelledMesh(walls.vertices_m, walls.faces,
                                                            label, walls.face_facade))
    t = import_labelled_mesh(tmp_path / "walls.ply").truth
    assert t.facade_area_m2 == pytest.approx(2 * (10 + 8) * 3, rel=1e-9)
    assert [f.facade_area_m2 for f in t.facades] == pytest.approx([24, 30, 24, 30], rel=1e-9)
    assert t.footprint_area_m2 == pytest.approx(80.0, rel=1e-9)
