"""Camera sampling: Algorithm-1 orbit views meet their conditions; ideal and multi views."""

import itertools

import numpy as np
import pytest
import trimesh

from dataset.rendering.facade_views import FacadeViewConfig, ideal_views, multi_views
from dataset.rendering.orbit_views import OrbitConfig, orbit_view_failures, sample_orbit_views
from dataset.rendering.render import Raycaster, render_ground_truth
from envelope.camera import Intrinsics, look_at, project_world_to_image
from envelope.classes import SemanticClass
from envelope.mesh import LabelledMesh, concatenate_meshes
from envelope.truth import Building

K = Intrinsics.from_fov(128, 128, 60.0)


@pytest.fixture(scope="module")
def box_raycaster(box_building):
    return Raycaster(box_building.mesh)


def _box_facade_corners(truth, facade_id):
    """(4, 3) corners of the box's facade, from the truth (box centred at the origin)."""
    n = np.asarray(truth.facade(facade_id).normal)
    sx, sy = 20.0, 12.0  # BOX_SIZE_M
    half_depth = sx / 2 if abs(n[0]) > 0.5 else sy / 2
    half_width = truth.facade(facade_id).width_m / 2
    right = np.cross([0.0, 0.0, 1.0], n)
    h = truth.facade(facade_id).height_m
    return np.array([half_depth * n + a * half_width * right + [0, 0, z]
                     for a, z in ((-1, 0), (1, 0), (1, h), (-1, h))])


def test_orbit_views_meet_the_boundary_conditions(box_building, box_raycaster):
    config = OrbitConfig()
    poses = sample_orbit_views(box_building, box_raycaster, K, 24, config=config, seed=7)
    assert len(poses) == 24
    for pose in poses:
        assert orbit_view_failures(box_raycaster, K, pose, config) == ()
        # Looking at the point of interest: the box centre projects near the image centre.
        uv, depth = project_world_to_image(np.array([0.0, 0.0, 4.5]), K, pose)
        assert depth > 0 and np.allclose(uv, [64.0, 64.0], atol=1e-6)
    # Spread: no two viewing directions closer than the Poisson-disc angle.
    dirs = np.array([p[:3, 3] - [0.0, 0.0, 4.5] for p in poses])
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    lo, hi = np.deg2rad(config.elevation_deg)
    min_angle = config.separation * np.sqrt(2 * np.pi * (np.sin(hi) - np.sin(lo)) / 24)
    cos = dirs @ dirs.T
    np.fill_diagonal(cos, -1.0)
    assert np.arccos(cos.max()) >= min_angle - 1e-9


def test_orbit_views_are_deterministic(box_building, box_raycaster):
    a = sample_orbit_views(box_building, box_raycaster, K, 6, config=OrbitConfig(), seed=1)
    b = sample_orbit_views(box_building, box_raycaster, K, 6, config=OrbitConfig(), seed=1)
    c = sample_orbit_views(box_building, box_raycaster, K, 6, config=OrbitConfig(), seed=2)
    np.testing.assert_array_equal(np.array(a), np.array(b))
    assert not np.allclose(np.array(a), np.array(c))


def test_camera_under_a_slab_is_refused():
    slab = trimesh.creation.box(bounds=[[-5.0, -5.0, 3.0], [5.0, 5.0, 3.3]])
    rc = Raycaster.from_triangles(slab.vertices, slab.faces)
    failures = orbit_view_failures(rc, K, look_at([0.0, 0.0, 1.6], [0.0, 4.0, 3.0]),
                                   OrbitConfig())
    assert "under_building" in failures and "inside_building" not in failures


def test_failures_are_reported(box_raycaster):
    config = OrbitConfig()
    assert "inside_building" in orbit_view_failures(
        box_raycaster, K, look_at([0.0, 0.0, 4.0], [5.0, 0.0, 4.0]), config)
    assert "below_ground" in orbit_view_failures(
        box_raycaster, K, look_at([0.0, -60.0, 0.5], [0.0, 0.0, 4.5]), config)
    assert "touches_border" in orbit_view_failures(
        box_raycaster, K, look_at([0.0, -14.0, 4.5], [0.0, 0.0, 4.5]), config)
    assert "too_small" in orbit_view_failures(
        box_raycaster, K, look_at([0.0, -400.0, 4.5], [0.0, 0.0, 4.5]), config)
    assert "not_visible" in orbit_view_failures(
        box_raycaster, K, look_at([0.0, -40.0, 4.5], [0.0, -80.0, 4.5]), config)


def test_ideal_views_look_along_the_normal_and_see_all_corners(box_building, box_raycaster):
    views = ideal_views(box_building, box_raycaster, K, config=FacadeViewConfig())
    assert [fid for fid, _ in views] == [1, 2, 3, 4]
    for fid, pose in views:
        normal = np.asarray(box_building.truth.facade(fid).normal)
        optical_axis = -pose[:3, 2]
        angle = np.degrees(np.arccos(np.clip(optical_axis @ -normal, -1, 1)))
        assert angle < 1.0
        uv, depth = project_world_to_image(_box_facade_corners(box_building.truth, fid), K, pose)
        assert (depth > 0).all()
        assert (uv >= 0).all() and (uv <= 128).all()
        # The facade fills the frame up to the margin along its limiting axis.
        spread = np.ptp(uv, axis=0).max() / 128
        assert spread == pytest.approx(1 - 2 * FacadeViewConfig().margin, abs=1e-6)
        ids = render_ground_truth(box_raycaster, K, pose).facade_ids
        assert (ids[64, 64] == fid) and set(np.unique(ids)) <= {0, fid}


def test_multi_views_five_per_facade_pairwise_distinct(box_building, box_raycaster):
    config = FacadeViewConfig()
    views = multi_views(box_building, box_raycaster, K, config=config, seed=3)
    assert [fid for fid, _ in views] == [f for f in (1, 2, 3, 4) for _ in range(5)]
    for (_, pa), (_, pb) in itertools.combinations(views, 2):
        assert np.linalg.norm(pa[:3, 3] - pb[:3, 3]) > 0.5  # distinct positions
    for fid, pose in views:
        eye = pose[:3, 3]
        assert eye[2] >= config.eye_height_m - 1e-9
        assert eye[2] <= 4.5 + 1e-9  # at most mid-facade
        normal = np.asarray(box_building.truth.facade(fid).normal)
        off_normal = np.degrees(np.arccos(np.clip((eye[:2] @ normal[:2])
                                                  / np.linalg.norm(eye[:2]), -1, 1)))
        assert off_normal < 60  # in front of the facade, roughly within the azimuth spread
        uv, depth = project_world_to_image(_box_facade_corners(box_building.truth, fid), K, pose)
        assert (depth > 0).all() and (uv >= 0).all() and (uv <= 128).all()
        assert (render_ground_truth(box_raycaster, K, pose).facade_ids == fid).mean() > 0.05
    again = multi_views(box_building, box_raycaster, K, config=config, seed=3)
    np.testing.assert_array_equal(np.array([p for _, p in views]),
                                  np.array([p for _, p in again]))


def test_hidden_facade_gets_no_views_and_a_warning(box_building):
    # A 30 m x 12 m screen 3 m in front of facade 1 (y = -6) hides it from every view.
    screen = trimesh.creation.box([30.0, 0.2, 12.0])
    screen.apply_translation([0.0, -9.0, 6.0])
    mesh = concatenate_meshes([box_building.mesh, LabelledMesh(
        screen.vertices, screen.faces, [SemanticClass.OTHER] * 12, [0] * 12)])
    building = Building(mesh, box_building.truth)
    rc = Raycaster(mesh)
    config = FacadeViewConfig(max_attempts=4)
    with pytest.warns(UserWarning, match="facade 1 gets no ideal view"):
        ideal = ideal_views(building, rc, K, config=config)
    assert [fid for fid, _ in ideal] == [2, 3, 4]
    with pytest.warns(UserWarning, match="facade 1 multi view"):
        multi = multi_views(building, rc, K, config=config, seed=0)
    assert {fid for fid, _ in multi} == {2, 3, 4} and len(multi) == 15


def test_a_building_that_cannot_be_framed_is_refused(box_building, box_raycaster):
    impossible = OrbitConfig(min_coverage=0.9, max_attempts=3, max_adjustments=2)
    with pytest.raises(ValueError, match="cannot frame building 'box'"):
        sample_orbit_views(box_building, box_raycaster, K, 2, config=impossible, seed=0)
    with pytest.raises(ValueError, match="at least one orbit view"):
        sample_orbit_views(box_building, box_raycaster, K, 0, config=OrbitConfig(), seed=0)


def test_bad_configs_are_refused():
    with pytest.raises(ValueError, match="elevation_deg"):
        OrbitConfig(elevation_deg=(50.0, 10.0))
    with pytest.raises(ValueError, match="margin"):
        OrbitConfig(margin=0.6)
    with pytest.raises(ValueError, match="multi_count"):
        FacadeViewConfig(multi_count=0)
    with pytest.raises(ValueError, match="multi_distance_factor"):
        FacadeViewConfig(multi_distance_factor=(2.0, 1.0))
