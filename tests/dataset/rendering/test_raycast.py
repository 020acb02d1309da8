"""envelope.geometry.raycast: the one ray caster and its inside rule (winding numbers).

Rendering, visibility, sections and camera checks all cast through :class:`Raycaster`; on a
thin wall with a window opening, made of four touching boxes, they see the same hits and
make the same inside decisions.
"""

import numpy as np
import pytest
import trimesh
from shapely.geometry import Point

from dataset.rendering.render import render_ground_truth
from dataset.rendering.section import cross_section_footprint
from envelope.camera import Intrinsics, look_at, rays_world
from envelope.classes import SemanticClass
from envelope.geometry.raycast import Raycaster, winding_numbers
from envelope.geometry.visibility import escape_fractions
from envelope.mesh import LabelledMesh


def _boxes(*bounds) -> LabelledMesh:
    """Touching or overlapping closed boxes (lo, hi) as one mesh, each with its own vertices."""
    parts = [trimesh.creation.box(bounds=np.array(b, dtype=float)) for b in bounds]
    mesh = trimesh.util.concatenate(parts)
    n = len(mesh.faces)
    return LabelledMesh(mesh.vertices, mesh.faces, np.full(n, SemanticClass.WALL),
                        np.zeros(n, dtype=np.int32))


# A 4 m x 3 m wall, 2 cm thick, with a 1 x 1 m window opening: four touching boxes.
THIN_WALL = _boxes(((-2, -0.01, 0), (2, 0.01, 1)), ((-2, -0.01, 2), (2, 0.01, 3)),
                   ((-2, -0.01, 1), (-0.5, 0.01, 2)), ((0.5, -0.01, 1), (2, 0.01, 2)))


def test_winding_numbers_count_bodies():
    cube = trimesh.creation.box(bounds=[[0, 0, 0], [1, 1, 1]])
    other = trimesh.creation.box(bounds=[[0.5, 0, 0], [1.5, 1, 1]])
    both = trimesh.util.concatenate([cube, other])
    points = np.array([[0.25, 0.5, 0.5], [0.75, 0.5, 0.5], [1.25, 0.5, 0.5], [2, 0.5, 0.5]])
    w = winding_numbers(both.triangles, points)
    np.testing.assert_allclose(w, [1, 2, 1, 0], atol=1e-12)
    rc = Raycaster.from_triangles(both.vertices, both.faces)
    np.testing.assert_array_equal(rc.contains(points), [True, True, True, False])  # union
    # A point's value does not depend on the other points asked with it: bitwise equal.
    np.testing.assert_array_equal(rc.winding_numbers(points[1:2]), rc.winding_numbers(points)[1:2])
    room = trimesh.creation.box(bounds=[[0.2, 0.2, 0.2], [0.8, 0.8, 0.8]])
    room.invert()  # a hollow cube: its room is outside
    hollow = trimesh.util.concatenate([cube, room])
    np.testing.assert_allclose(winding_numbers(hollow.triangles, [[0.5, 0.5, 0.5],
                                                                   [0.1, 0.5, 0.5]]),
                               [0, 1], atol=1e-12)


def test_thin_wall_rendering_and_rays_see_the_same_hits():
    rc = Raycaster(THIN_WALL)
    intrinsics = Intrinsics(fx=40.0, fy=40.0, cx=32.0, cy=24.0, width=64, height=48)
    pose = look_at(np.array([0.3, -4.0, 1.6]), np.array([0.0, 0.0, 1.5]))
    images = render_ground_truth(rc, intrinsics, pose)
    origins, dirs = rays_world(intrinsics, pose)
    origins, dirs = origins.reshape(-1, 3), dirs.reshape(-1, 3)
    hit = (images.labels > 0).reshape(-1)
    np.testing.assert_array_equal(hit, rc.occluded(origins, dirs))
    face, _ = rc.first_hit(origins, dirs)
    np.testing.assert_array_equal(hit, face >= 0)
    # Through the opening the rays miss: a hole of background amid the wall.
    through = ~hit & (np.abs(origins + 4.0 / dirs[:, 1:2] * dirs)[:, 0] < 0.45)
    assert through.sum() > 50
    # Visibility from the wall's front: a ray leaves exactly when the render would miss.
    front = THIN_WALL.triangles_m[THIN_WALL.face_normals()[:, 1] < -0.5]
    fractions = escape_fractions(rc, front, np.tile([0.0, -1.0, 0.0], (len(front), 1)),
                                 rays_per_sample=8, offset_m=1e-3, ground=True)
    assert (fractions > 0.3).all()


def test_thin_wall_sections_and_inside_tests_agree():
    rc = Raycaster(THIN_WALL)
    for z, area in ((1.5, 2 * 1.5 * 0.02), (0.5, 4 * 0.02)):
        footprint = cross_section_footprint(rc, z)
        assert footprint.area == pytest.approx(area, rel=1e-9)
        x, y = np.meshgrid(np.linspace(-2.51, 2.49, 101), np.linspace(-0.0195, 0.0195, 7))
        points = np.stack([x.ravel(), y.ravel(), np.full(x.size, z)], axis=1)  # none on a face
        in_section = np.array([footprint.contains(Point(p[:2])) for p in points])
        np.testing.assert_array_equal(in_section, rc.contains(points))
    # A camera in the opening is outside; one inside the wall is inside.
    np.testing.assert_array_equal(rc.contains([[0.0, 0.0, 1.5], [-1.0, 0.0, 1.5]]),
                                  [False, True])
