"""Planar faces -> labelled mesh: areas, orientation, T-junction repair, extrusion, bad input."""

import numpy as np
import pytest
import trimesh
from shapely.geometry import Polygon, box

from dataset.families.polygon_mesh import (
    PlanarFace,
    extruded_faces,
    face_polygon_2d,
    plane_basis,
    swept_faces,
    triangulate_faces,
    vertical_quad,
)
from envelope.classes import SemanticClass

UP = np.array([0.0, 0.0, 1.0])


def _square(x0, y0, x1, y1, z=0.0):
    return np.array([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]])


def test_plane_basis_is_right_handed_and_orthonormal():
    for n in ([0, 0, 1.0], [0, -1.0, 0], [0.6, 0.8, 0], [1.0, 0, 0]):
        b = plane_basis(np.array(n))
        np.testing.assert_allclose(b @ b.T, np.eye(2), atol=1e-12)
        np.testing.assert_allclose(np.cross(b[0], b[1]), n, atol=1e-12)


def test_face_with_hole_has_exact_area_and_faces_its_normal():
    face = PlanarFace((_square(0, 0, 2, 2), _square(0.5, 0.5, 1.5, 1.0)), -UP, SemanticClass.ROOF)
    mesh = triangulate_faces([face])
    assert mesh.face_areas_m2().sum() == pytest.approx(4.0 - 0.5, rel=1e-12)
    np.testing.assert_allclose(mesh.face_normals(), np.tile(-UP, (len(mesh.faces), 1)), atol=1e-12)
    assert face_polygon_2d(face).area == pytest.approx(3.5)
    assert set(mesh.face_label.tolist()) == {SemanticClass.ROOF}


def test_aligned_holes_leave_no_t_junctions():
    # A grid of windows (rows and columns aligned) makes earcut emit zero-area triangles and
    # edges through hole corners; the repair must give every hole corner to the triangles
    # around it, so the wall closes with the reveals.
    holes = [_square(0.5 + 2 * c, 0.9 + 3 * r, 1.7 + 2 * c, 2.3 + 3 * r)
             for c in range(2) for r in range(2)]
    face = PlanarFace((_square(0, 0, 4.4, 7), *holes), UP, SemanticClass.WALL)
    mesh = triangulate_faces([face])
    assert mesh.face_areas_m2().min() > 1e-6
    assert mesh.face_areas_m2().sum() == pytest.approx(4.4 * 7 - 4 * 1.2 * 1.4, rel=1e-12)
    corners = {tuple(p) for h in holes for p in h}
    used = {tuple(v) for v in mesh.vertices_m[np.unique(mesh.faces)]}
    assert corners <= used
    # No vertex lies inside any triangle edge.
    tri = mesh.triangles_m
    for k in range(3):
        a, b = tri[:, k], tri[:, (k + 1) % 3]
        for v in mesh.vertices_m:
            t = np.einsum("ij,ij->i", v - a, b - a) / np.einsum("ij,ij->i", b - a, b - a)
            dist = np.linalg.norm(a + t[:, None] * (b - a) - v, axis=1)
            assert not np.any((dist < 1e-9) & (t > 1e-9) & (t < 1 - 1e-9))


@pytest.mark.parametrize(
    "polygon",
    [box(0, 0, 3, 2), Polygon([(0, 0), (4, 0), (4, 1), (1, 1), (1, 3), (0, 3)]),
     box(0, 0, 4, 4).difference(box(1, 1, 3, 2))],
)
def test_extrusion_is_closed_with_exact_volume(polygon):
    mesh = triangulate_faces(extruded_faces(polygon, 1.0, 3.5, label=SemanticClass.OTHER))
    tm = trimesh.Trimesh(mesh.vertices_m, mesh.faces, process=False)
    assert tm.is_watertight and tm.is_winding_consistent
    assert tm.volume == pytest.approx(polygon.area * 2.5, rel=1e-12)
    assert mesh.face_areas_m2().sum() == pytest.approx(
        2 * polygon.area + polygon.length * 2.5, rel=1e-12
    )


@pytest.mark.parametrize("reverse", [False, True])
def test_sweep_is_closed_with_exact_volume_either_ring_orientation(reverse):
    ring = np.array([[0, -5, 6], [0, 0, 9], [0, 5, 6], [0, 5, 6.2], [0, 0, 9.2], [0, -5, 6.2]])
    ring = ring[::-1] if reverse else ring
    mesh = triangulate_faces(swept_faces(ring.astype(float), np.array([10.0, 0, 0]), label=3))
    tm = trimesh.Trimesh(mesh.vertices_m, mesh.faces, process=False)
    assert tm.is_watertight and tm.is_winding_consistent
    assert tm.volume == pytest.approx(2 * 5 * 0.2 * 10, rel=1e-12)
    with pytest.raises(ValueError, match="perpendicular"):
        swept_faces(ring.astype(float), np.array([1.0, 1.0, 0]), label=3)


def test_vertical_quad_faces_right_of_its_edge():
    face = vertical_quad(np.array([0.0, 0.0]), np.array([2.0, 0.0]), 0.0, 3.0, label=1)
    np.testing.assert_allclose(face.normal, [0, -1, 0])
    assert triangulate_faces([face]).face_areas_m2().sum() == pytest.approx(6.0)


def test_equal_vertices_of_different_faces_merge_deterministically():
    a = PlanarFace((_square(0, 0, 1, 1),), UP, 1)
    b = PlanarFace((_square(1, 0, 2, 1),), UP, 2)
    m1, m2 = triangulate_faces([a, b]), triangulate_faces([a, b])
    assert len(m1.vertices_m) == 6
    np.testing.assert_array_equal(m1.vertices_m, m2.vertices_m)
    np.testing.assert_array_equal(m1.faces, m2.faces)


def test_bad_input_raises_helpful_errors():
    with pytest.raises(ValueError, match="unit vector"):
        PlanarFace((_square(0, 0, 1, 1),), np.array([0, 0, 2.0]), 1)
    with pytest.raises(ValueError, match="n >= 3"):
        PlanarFace((np.zeros((2, 3)),), UP, 1)
    with pytest.raises(ValueError, match="unknown class"):
        PlanarFace((_square(0, 0, 1, 1),), UP, 17)
    with pytest.raises(ValueError, match="at least one face"):
        triangulate_faces([])
    with pytest.raises(ValueError, match="z1 > z0"):
        extruded_faces(box(0, 0, 1, 1), 2.0, 1.0, label=1)
    with pytest.raises(ValueError, match="no area"):
        triangulate_faces([PlanarFace((np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0.0]]),), UP, 1)])
