"""Prism walls and roofs close a solid whose volume and areas have closed forms."""

import numpy as np
import pytest
import trimesh

from dataset.families.facade_geometry import wall_faces
from dataset.families.polygon_mesh import triangulate_faces
from dataset.families.prism import (
    edge_frames,
    gable_roof_faces,
    gable_roof_shell_faces,
    gable_walls,
    ground_face,
    offset_ring,
    overhang_roof_faces,
    parapet_roof_faces,
    prism_walls,
    validate_footprint,
)
from envelope.classes import SemanticClass

RECT = np.array([[-4.0, -3.0], [4.0, -3.0], [4.0, 3.0], [-4.0, 3.0]])
L_SHAPE = np.array([[0.0, 0], [10, 0], [10, 4], [4, 4], [4, 9], [0, 9]])


def _shoelace_m2(ring):
    x, y = ring[:, 0], ring[:, 1]
    return abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))) / 2


def _solid(walls, other):
    faces = [f for w in walls for f in wall_faces(w)] + other
    mesh = triangulate_faces(faces)
    tm = trimesh.Trimesh(mesh.vertices_m, mesh.faces, process=False)
    assert tm.is_watertight and tm.is_winding_consistent
    return mesh, tm


@pytest.mark.parametrize("footprint", [RECT, L_SHAPE])
def test_parapet_roof_closes_the_prism(footprint):
    area = _shoelace_m2(footprint)
    walls = prism_walls(footprint, 10.0, list(range(1, len(footprint) + 1)))
    roof = parapet_roof_faces(footprint, 9.0, 1.0, 0.3)
    mesh, tm = _solid(walls, [ground_face(footprint), *roof])
    inner = offset_ring(footprint, -0.3)
    inner_area = _shoelace_m2(inner)
    assert tm.volume == pytest.approx(area * 10.0 - inner_area * 1.0, rel=1e-12)
    roof = mesh.face_areas_m2()[mesh.face_label == SemanticClass.ROOF].sum()
    inner_perimeter = np.linalg.norm(np.roll(inner, -1, axis=0) - inner, axis=1).sum()
    assert roof == pytest.approx(area + inner_perimeter * 1.0, rel=1e-12)


def test_overhang_roof_closes_the_prism():
    walls = prism_walls(RECT, 9.0, [1, 2, 3, 4])
    _, tm = _solid(walls, [ground_face(RECT), *overhang_roof_faces(RECT, 9.0, 0.5, 0.3)])
    assert tm.volume == pytest.approx(48.0 * 9.0 + 9.0 * 7.0 * 0.3, rel=1e-12)


def test_gable_roof_volume_and_gable_walls():
    walls = gable_walls(RECT, 6.0, 9.0, [1, 2, 3, 4])
    _, tm = _solid(walls, [ground_face(RECT), *gable_roof_faces(walls)])
    assert tm.volume == pytest.approx(48.0 * 6.0 + 8.0 * 6.0 * 3.0 / 2, rel=1e-12)
    # Gable walls (edges 1 and 3, 6 m wide) include their triangle; eave walls do not.
    assert walls[1].gross_area_m2() == pytest.approx(6.0 * 6.0 + 6.0 * 3.0 / 2)
    assert walls[0].gross_area_m2() == pytest.approx(8.0 * 6.0)
    assert walls[1].height_m == 9.0


def test_gable_roof_shell_overhangs_and_floats_above_the_roof():
    walls = gable_walls(RECT, 6.0, 9.0, [1, 2, 3, 4])  # 8 m ridge along x, 6 m across
    faces, top = gable_roof_shell_faces(walls, 0.5, 0.2, 0.01)
    mesh = triangulate_faces(faces)
    tm = trimesh.Trimesh(mesh.vertices_m, mesh.faces, process=False)
    assert tm.is_watertight and tm.is_winding_consistent
    cos = 3.0 / np.hypot(3.0, 3.0)
    # Cross-section: two strips 3.5 m wide (horizontally) and 0.2 / cos thick (vertically).
    # rel 1e-8: the slab's irrational corners are rounded to 1 nm when vertices merge.
    assert tm.volume == pytest.approx(2 * 3.5 * 0.2 / cos * 9.0, rel=1e-8)
    assert top == pytest.approx(9.0 + 0.21 / cos)
    np.testing.assert_allclose(tm.bounds[:, :2], [[-4.5, -3.5], [4.5, 3.5]], atol=1e-12)
    # 1 cm above the roof plane over the eaves wall (y = -3): z = 6 + 0.01 / cos.
    assert tm.bounds[0, 2] == pytest.approx(6.0 + 0.01 / cos - 0.5)
    with pytest.raises(ValueError, match="must be > 0"):
        gable_roof_shell_faces(walls, 0.5, 0.0, 0.01)


def test_offset_ring_of_a_rectangle():
    np.testing.assert_allclose(offset_ring(RECT, 0.5), [[-4.5, -3.5], [4.5, -3.5], [4.5, 3.5],
                                                         [-4.5, 3.5]])


def test_edge_frames_face_outward():
    normals = [f.normal[:2] for f in edge_frames(L_SHAPE)]
    np.testing.assert_allclose(normals, [[0, -1], [1, 0], [0, 1], [1, 0], [0, 1], [-1, 0]],
                               atol=1e-15)


def test_bad_footprints_and_roofs_raise():
    with pytest.raises(ValueError, match="counter-clockwise"):
        validate_footprint(RECT[::-1])
    with pytest.raises(ValueError, match="simple polygon"):
        validate_footprint(np.array([[0.0, 0], [1, 1], [1, 0], [0, 1]]))
    with pytest.raises(ValueError, match="shape"):
        validate_footprint(np.zeros((2, 2)))
    with pytest.raises(ValueError, match="rectangular footprint"):
        gable_walls(L_SHAPE, 6.0, 9.0, [1, 2, 3, 4, 5, 6])
    with pytest.raises(ValueError, match="eave < ridge"):
        gable_walls(RECT, 6.0, 5.0, [1, 2, 3, 4])
    with pytest.raises(ValueError, match="wall height must be > 0"):
        prism_walls(RECT, 0.0, [1, 2, 3, 4])
    with pytest.raises(ValueError, match="one facade id"):
        prism_walls(RECT, 3.0, [1, 2])
    with pytest.raises(ValueError, match="splits or removes"):
        offset_ring(RECT, -3.5)
    with pytest.raises(ValueError, match="> 0 m"):
        parapet_roof_faces(RECT, 9.0, 0.0, 0.3)
