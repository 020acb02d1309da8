"""envelope.geometry.visibility: ray directions, escape fractions on convex and nested boxes."""

import numpy as np
import pytest
import trimesh

from envelope.geometry.raycast import Raycaster
from envelope.geometry.visibility import MIN_RAY_COSINE, escape_fractions, hemisphere_directions


def _normals(tri):
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def test_hemisphere_directions_are_unit_and_above_the_plane():
    d = hemisphere_directions(64)
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0, atol=1e-12)
    assert d[:, 2].min() >= MIN_RAY_COSINE and d[:, 2].max() <= 1.0
    # Spread evenly in azimuth: the mean horizontal direction is near zero.
    assert np.linalg.norm(d[:, :2].mean(axis=0)) < 0.05
    with pytest.raises(ValueError, match="at least one"):
        hemisphere_directions(0)


def test_convex_box_sees_everything_and_a_nested_box_nothing():
    outer = trimesh.creation.box([10.0, 8.0, 6.0])
    inner = trimesh.creation.box([2.0, 2.0, 2.0])
    mesh = trimesh.util.concatenate([outer, inner])
    tri = mesh.triangles
    f = escape_fractions(Raycaster.from_triangles(mesh.vertices, mesh.faces), tri, _normals(tri),
                         rays_per_sample=16, offset_m=1e-3)
    np.testing.assert_array_equal(f[: len(outer.faces)], 1.0)  # convex: every ray escapes
    np.testing.assert_array_equal(f[len(outer.faces):], 0.0)  # enclosed: none does
    degenerate = escape_fractions(Raycaster.from_triangles(mesh.vertices, mesh.faces), tri[:1],
                                  np.zeros((1, 3)), rays_per_sample=4, offset_m=1e-3)
    np.testing.assert_array_equal(degenerate, 0.0)


def test_open_to_sky():
    box = trimesh.creation.box([2.0, 2.0, 2.0])
    rc = Raycaster.from_triangles(box.vertices + [0, 0, 5], box.faces)
    np.testing.assert_array_equal(rc.open_to_sky([[0, 0, 0], [3, 0, 0]]), [False, True])


def test_ground_stops_downward_rays():
    # An open-bottomed box (walls and roof, no floor): the inner wall sides see out through
    # the bottom unless the ground stops the rays that point down.
    box = trimesh.creation.box([4.0, 4.0, 3.0])
    box.apply_translation([0, 0, 1.5])
    walls_and_roof = box.faces[box.face_normals[:, 2] > -0.5]
    inner = walls_and_roof[:, ::-1]  # the same faces seen from inside
    tri = box.vertices[inner]
    rc = Raycaster.from_triangles(box.vertices, walls_and_roof)
    open_below = escape_fractions(rc, tri, _normals(tri), rays_per_sample=16, offset_m=1e-3)
    grounded = escape_fractions(rc, tri, _normals(tri), rays_per_sample=16, offset_m=1e-3,
                                ground=True)
    assert open_below[np.abs(_normals(tri)[:, 2]) < 0.5].min() > 0.02
    np.testing.assert_array_equal(grounded, 0.0)


def test_a_ground_box_lets_the_wall_under_an_eave_see_down_past_it():
    # A 4 x 4 x 3 m box under a roof slab that overhangs 1 m all round, with a fascia
    # hanging 0.4 m from the slab's edge: the wall's top 0.2 m sees the slab above and the
    # fascia straight out, so only downward rays leave. A ground without end stops them
    # all; the ground in the mesh's x/y box lets those that pass under the fascia go.
    parts = [trimesh.creation.box([4.0, 4.0, 3.0]), trimesh.creation.box([6.0, 6.0, 0.2]),
             *[trimesh.creation.box(size) for size in ([0.05, 6.0, 0.4], [0.05, 6.0, 0.4])]]
    for part, shift in zip(parts, ([0, 0, 1.5], [0, 0, 3.1], [2.975, 0, 2.8], [-2.975, 0, 2.8])):
        part.apply_translation(shift)
    mesh = trimesh.util.concatenate(parts)
    rc = Raycaster.from_triangles(mesh.vertices, mesh.faces)
    band = np.array([[[2.0, -0.5, 2.8], [2.0, 0.5, 2.8], [2.0, 0.0, 3.0]]])  # facing +x
    box_xy = np.array([[-3.0, -3.0], [3.0, 3.0]])

    def fraction(**ground):
        return escape_fractions(rc, band, _normals(band), rays_per_sample=64, offset_m=1e-3,
                                **ground)[0]

    assert fraction(ground=True) == 0.0
    assert fraction(ground=True, ground_box_xy_m=box_xy) > 0.02
    assert fraction(ground=True, ground_box_xy_m=box_xy) < fraction()  # the ground still counts
    # the inner sides of an open-bottomed box meet the ground inside its box: still nothing
    box = trimesh.creation.box([4.0, 4.0, 3.0])
    box.apply_translation([0, 0, 1.5])
    walls_and_roof = box.faces[box.face_normals[:, 2] > -0.5]
    tri = box.vertices[walls_and_roof[:, ::-1]]
    inner = escape_fractions(Raycaster.from_triangles(box.vertices, walls_and_roof), tri,
                             _normals(tri), rays_per_sample=16, offset_m=1e-3, ground=True,
                             ground_box_xy_m=np.array([[-2.0, -2.0], [2.0, 2.0]]))
    np.testing.assert_array_equal(inner, 0.0)


def test_bad_shapes_are_refused():
    box = trimesh.creation.box()
    with pytest.raises(ValueError, match=r"\(F, 3, 3\)"):
        escape_fractions(Raycaster.from_triangles(box.vertices, box.faces), np.zeros((2, 3)),
                         np.zeros((2, 3)), rays_per_sample=4, offset_m=1e-3)
