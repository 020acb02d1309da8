"""Renderer: exact depth, per-pixel labels, back-projection onto the mesh, RGB, bad inputs."""

import sys

import numpy as np
import pytest
import trimesh

from dataset.rendering.render import (
    Raycaster,
    RgbConfig,
    render_ground_truth,
    render_rgb,
    render_view,
)
from dataset.rendering.shading import sample_look
from envelope.camera import (
    Intrinsics,
    look_at,
    pixel_centres,
    rays_world,
    unproject_depth_to_world,
)
from envelope.classes import SemanticClass
from envelope.mesh import LabelledMesh, concatenate_meshes

K = Intrinsics.from_fov(160, 120, 60.0)
# Oblique view of the box's -y and -x facades and its roof (generic: no pixel ray
# runs along a box edge).
POSE = look_at([-23.3, -31.7, 14.2], [0.7, 0.4, 3.9])


@pytest.fixture(scope="module")
def box_raycaster(box_building):
    return Raycaster(box_building.mesh)


def _analytic_box_depth(intrinsics, pose, lo, hi):
    """z-depth of the first hit with the axis-aligned box [lo, hi] (slab method), 0 for none."""
    o, d = rays_world(intrinsics, pose)
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = (lo - o) / d, (hi - o) / d
    t_near = np.minimum(t1, t2).max(axis=-1)
    t_far = np.maximum(t1, t2).min(axis=-1)
    hit = (t_near <= t_far) & (t_near > 0)
    return np.where(hit, t_near, 0.0)


def _first_triangle_brute_force(triangles, origins, dirs):
    """Index of the nearest triangle hit by each ray (Moller-Trumbore over all pairs), -1 none."""
    v0 = triangles[:, 0]
    e1, e2 = triangles[:, 1] - v0, triangles[:, 2] - v0
    p = np.cross(dirs[:, None], e2[None])
    det = np.einsum("rtk,tk->rt", p, e1)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = origins[:, None] - v0[None]
        u = np.einsum("rtk,rtk->rt", s, p) / det
        q = np.cross(s, e1[None])
        v = np.einsum("rk,rtk->rt", dirs, q) / det
        t = np.einsum("tk,rtk->rt", e2, q) / det
    ok = (np.abs(det) > 1e-12) & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0)
    t = np.where(ok, t, np.inf)
    return np.where(ok.any(axis=1), t.argmin(axis=1), -1)


def test_depth_equals_analytic_z_depth_of_box(box_building, box_raycaster):
    gt = render_ground_truth(box_raycaster, K, POSE)
    lo, hi = box_building.mesh.vertices_m.min(axis=0), box_building.mesh.vertices_m.max(axis=0)
    expected = _analytic_box_depth(K, POSE, lo, hi)
    hit = gt.depth_z_m > 0
    np.testing.assert_array_equal(hit, expected > 0)
    assert hit.mean() > 0.1  # the box fills a good part of the view
    rel = np.abs(gt.depth_z_m[hit] - expected[hit]) / expected[hit]
    assert rel.max() <= 1e-4  # float32 storage: ~6e-8 in practice


def test_fronto_parallel_depth_is_the_plane_distance(box_raycaster):
    # Facade 1 is the plane y = -6; a camera at y = -26 looking along +y sees it at 20 m.
    pose = look_at([0.0, -26.0, 4.0], [0.0, 0.0, 4.0])
    gt = render_ground_truth(box_raycaster, Intrinsics.from_fov(64, 64, 20.0), pose)
    assert (gt.depth_z_m > 0).all()
    np.testing.assert_allclose(gt.depth_z_m, 20.0, rtol=1e-6)
    assert (gt.facade_ids == 1).all()
    np.testing.assert_allclose(gt.normals_world.reshape(-1, 3), [[0.0, -1.0, 0.0]] * 64 * 64)


def test_labels_and_facade_ids_are_those_of_the_hit_triangle(box_building, box_raycaster):
    gt = render_ground_truth(box_raycaster, K, POSE)
    # Independent float64 brute-force intersection on every 3rd pixel.
    o, d = rays_world(K, POSE)
    o, d = o[::3, ::3].reshape(-1, 3), d[::3, ::3].reshape(-1, 3)
    tri = _first_triangle_brute_force(box_building.mesh.triangles_m, o, d)
    hit = tri >= 0
    mesh = box_building.mesh
    labels = gt.labels[::3, ::3].reshape(-1)
    facades = gt.facade_ids[::3, ::3].reshape(-1)
    np.testing.assert_array_equal(labels[hit], mesh.face_label[tri[hit]])
    np.testing.assert_array_equal(facades[hit], mesh.face_facade[tri[hit]])
    assert (labels[~hit] == SemanticClass.BACKGROUND).all() and (facades[~hit] == 0).all()
    assert {1, 2, 3, 4} <= set(np.unique(gt.labels))  # wall, window, roof, door all seen


def test_back_projected_depth_lands_on_the_mesh(box_building, box_raycaster):
    gt = render_ground_truth(box_raycaster, K, POSE)
    hit = gt.depth_z_m > 0
    points = unproject_depth_to_world(pixel_centres(K)[hit], gt.depth_z_m[hit], K, POSE)
    lo, hi = box_building.mesh.vertices_m.min(axis=0), box_building.mesh.vertices_m.max(axis=0)
    # Distance of a point to the box surface: to the nearest of the six face planes,
    # for points within the box's extent (checked first).
    assert (points >= lo - 0.01).all() and (points <= hi + 0.01).all()
    to_planes = np.concatenate([np.abs(points - lo), np.abs(points - hi)], axis=1)
    assert to_planes.min(axis=1).max() < 0.01  # metres; float32 depth: ~1e-5 m in practice
    # Normals are the outward normals of the box face each point lies on.
    nearest = to_planes.argmin(axis=1)
    expected = np.zeros_like(points)
    expected[np.arange(len(points)), nearest % 3] = np.where(nearest < 3, -1.0, 1.0)
    np.testing.assert_allclose(gt.normals_world[hit], expected, atol=1e-6)


def test_background_pixels_are_empty(box_raycaster):
    gt = render_ground_truth(box_raycaster, K, look_at([0.0, -30.0, 40.0], [0.0, -30.0, 80.0]))
    assert (gt.depth_z_m == 0).all() and (gt.labels == 0).all() and (gt.facade_ids == 0).all()
    assert (gt.normals_world == 0).all()
    assert gt.depth_z_m.dtype == np.float32 and gt.facade_ids.dtype == np.int32


def test_contains_and_occluded(box_raycaster):
    inside = box_raycaster.contains(np.array([[0.0, 0.0, 4.5], [9.9, 5.9, 0.1], [30.0, 0, 4]]))
    np.testing.assert_array_equal(inside, [True, True, False])
    o = np.array([[0.0, -20.0, 4.0], [0.0, -20.0, 4.0]])
    d = np.array([[0.0, 1.0, 0.0], [0.0, -1.0, 0.0]])
    np.testing.assert_array_equal(box_raycaster.occluded(o, d), [True, False])
    # Limited to t_max: the wall at y = -6 lies 14 m away.
    np.testing.assert_array_equal(box_raycaster.occluded(o[:1], d[:1], t_max=13.0), [False])


def test_rgb_is_deterministic_and_varies_with_seed(box_raycaster):
    a = render_rgb(box_raycaster, K, POSE, seed=3)
    b = render_rgb(box_raycaster, K, POSE, seed=3)
    c = render_rgb(box_raycaster, K, POSE, seed=4)
    assert a.shape == (120, 160, 3) and a.dtype == np.uint8
    np.testing.assert_array_equal(a, b)
    assert np.abs(a.astype(int) - c.astype(int)).mean() > 5
    fine = render_rgb(box_raycaster, K, POSE, seed=3, supersampling=2)
    assert fine.shape == a.shape
    assert 0 < np.abs(fine.astype(int) - a.astype(int)).mean() < 20  # only edges and texture


def test_render_view_matches_the_separate_renders(box_raycaster):
    for s in (1, 2):
        gt, rgb = render_view(box_raycaster, K, POSE, seed=2, supersampling=s)
        np.testing.assert_array_equal(rgb, render_rgb(box_raycaster, K, POSE, seed=2,
                                                      supersampling=s))
        alone = render_ground_truth(box_raycaster, K, POSE)
        np.testing.assert_array_equal(gt.depth_z_m, alone.depth_z_m)
        np.testing.assert_array_equal(gt.facade_ids, alone.facade_ids)


def test_rgb_sky_above_ground_below(box_raycaster):
    # Looking level at the horizon, away from the building: sky on top is bluer than ground.
    pose = look_at([0.0, -40.0, 2.0], [0.0, -80.0, 2.0])
    rgb = render_rgb(box_raycaster, K, pose, seed=1).astype(float)
    sky, ground = rgb[5], rgb[-5]
    assert (sky[:, 2] - sky[:, 0]).mean() > 10  # blue sky
    assert np.abs(sky - ground).mean() > 10


def test_sun_shadow_darkens_the_shadowed_ground():
    seed = 5
    sun = sample_look(seed).sun_dir
    # A 40 m ground slab (class other) with a 4 m cube on it; the cube's shadow falls
    # on the slab at the top centre's projection along the sun.
    ground = trimesh.creation.box([40.0, 40.0, 0.2])
    ground.apply_translation([0, 0, -0.1])
    cube = trimesh.creation.box([4.0, 4.0, 4.0])
    cube.apply_translation([0, 0, 2.0])
    mesh = concatenate_meshes([
        LabelledMesh(m.vertices, m.faces, [lab] * len(m.faces), [0] * len(m.faces))
        for m, lab in ((ground, SemanticClass.OTHER), (cube, SemanticClass.OTHER))
    ])
    shadow_point = np.array([0.0, 0.0, 2.0]) - sun * (2.0 / sun[2])
    rc = Raycaster(mesh)
    k = Intrinsics.from_fov(65, 65, 40.0)
    pose = look_at(shadow_point + [0.0, -0.5, 30.0], shadow_point)
    centre = (32, 32)
    assert render_ground_truth(rc, k, pose).labels[centre] == SemanticClass.OTHER
    lit = render_rgb(rc, k, pose, seed=seed, config=RgbConfig(shadows=False))[centre]
    dark = render_rgb(rc, k, pose, seed=seed)[centre]
    assert dark.astype(int).sum() < 0.7 * lit.astype(int).sum()


def test_bad_inputs_are_refused(box_raycaster):
    with pytest.raises(ValueError, match="without faces"):
        Raycaster(LabelledMesh(np.zeros((0, 3)), np.zeros((0, 3), int), [], []))
    with pytest.raises(ValueError, match="LabelledMesh"):
        Raycaster("mesh.ply")
    with pytest.raises(ValueError, match=r"\(4, 4\)"):
        render_ground_truth(box_raycaster, K, np.eye(3))
    with pytest.raises(ValueError, match="rotation"):
        render_ground_truth(box_raycaster, K, np.diag([2.0, 1.0, 1.0, 1.0]))
    with pytest.raises(ValueError, match="Intrinsics"):
        render_ground_truth(box_raycaster, (100, 100), POSE)
    with pytest.raises(ValueError, match="supersampling"):
        render_rgb(box_raycaster, K, POSE, supersampling=0)
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        box_raycaster.first_hit(np.zeros((3, 3)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="wall_material"):
        RgbConfig(wall_material="marble")


def test_missing_embree_gives_the_install_hint(box_building, monkeypatch):
    monkeypatch.setitem(sys.modules, "embreex", None)  # makes `import embreex` fail
    with pytest.raises(ValueError, match="pip install embreex"):
        Raycaster(box_building.mesh)
