"""baselines.facade_mask: facade pixels, the centre component (2D-S), plane isolation (2D-SS)."""

import numpy as np
import pytest
from baselines_synthetic import facade_pose, render_facade, window_grid

from baselines.facade_mask import (
    PlaneIsolationConfig,
    centre_component,
    facade_class_mask,
    isolate_facade_2ds,
    isolate_facade_on_plane,
    tolerance_for_depth_steps,
)
from baselines.views import ViewError
from envelope.camera import Intrinsics, look_at
from envelope.classes import SemanticClass

L_M, H_M = 12.0, 9.0
K = Intrinsics.from_fov(256, 256, 60.0)


def _oblique(neighbour_m: float, recess_m: float = 0.2):
    pose = facade_pose(L_M, H_M, distance_m=16.0, azimuth_deg=35.0)
    wins = window_grid(L_M, H_M, 4, 3, 1.6, 1.5)
    return pose, render_facade(K, pose, length_m=L_M, height_m=H_M, windows=wins,
                               recess_m=recess_m, neighbour_m=neighbour_m)


def test_facade_classes_are_wall_window_door():
    labels = np.arange(6, dtype=np.uint8).reshape(2, 3)
    np.testing.assert_array_equal(facade_class_mask(labels),
                                  [[False, True, True], [False, True, False]])


def test_centre_component_or_the_one_nearest_the_centre():
    mask = np.zeros((9, 9), bool)
    mask[3:6, 3:6] = True  # holds the centre pixel (4, 4)
    mask[0, 0] = True
    np.testing.assert_array_equal(centre_component(mask), np.pad(np.ones((3, 3), bool), 3))
    mask[4, 4] = False  # centre not in the mask: the ring around it is still nearest
    assert centre_component(mask).sum() == 8
    with pytest.raises(ViewError, match="no facade pixels"):
        centre_component(np.zeros((4, 4), bool))


def test_2ds_mask_keeps_a_neighbour_joined_at_the_corner():
    _, (front_labels, _) = _oblique(neighbour_m=0.0)
    _, (labels, _) = _oblique(neighbour_m=6.0)
    front = facade_class_mask(front_labels)
    neighbour = facade_class_mask(labels) & ~front
    assert neighbour.sum() > 500  # the neighbour is clearly visible ...
    mask = isolate_facade_2ds(labels)
    assert (mask & neighbour).sum() == neighbour.sum()  # ... and 2D-S cannot tell it apart


def test_plane_isolation_drops_the_neighbour_and_keeps_recessed_windows():
    _, (front_labels, _) = _oblique(neighbour_m=0.0)
    pose, (labels, depth) = _oblique(neighbour_m=6.0)
    depth = np.round(depth * 1000) / 1000  # millimetre depth, as stored in the PNGs
    front = facade_class_mask(front_labels)
    neighbour = facade_class_mask(labels) & ~front
    mask, plane = isolate_facade_on_plane(labels, depth, K, PlaneIsolationConfig(),
                                          np.random.default_rng(0))
    # The walls meet along the corner; neighbour pixels within the wall tolerance
    # of the plane (at most about one column) may stay.
    assert 500 < neighbour.sum() and (mask & neighbour).sum() <= front.any(axis=1).sum()
    assert (front & ~mask).sum() <= 0.002 * front.sum()
    normal_camera = pose[:3, :3].T @ np.array([0.0, -1.0, 0.0])
    np.testing.assert_allclose(plane.normal, normal_camera, atol=1e-3)


def test_plane_isolation_refuses_views_without_facade_or_depth():
    _, (labels, depth) = _oblique(neighbour_m=0.0)
    cfg, rng = PlaneIsolationConfig(), np.random.default_rng(0)
    with pytest.raises(ViewError, match="no facade pixels"):
        isolate_facade_on_plane(np.zeros_like(labels), depth, K, cfg, rng)
    with pytest.raises(ViewError, match="no valid depth"):
        isolate_facade_on_plane(labels, np.zeros_like(depth), K, cfg, rng)
    with pytest.raises(ValueError, match="centre_fraction"):
        PlaneIsolationConfig(centre_fraction=0.0)


def test_plane_isolation_prefers_the_facade_at_the_centre_over_a_bigger_neighbour():
    # Aimed near the corner from far to the side: the 30 m neighbour fills more
    # of the central box than the target facade, which still holds the centre.
    pose = look_at([26.0, -10.0, 1.6], [11.2, 0.0, 4.5])
    labels, depth = render_facade(K, pose, length_m=L_M, height_m=H_M, windows=[],
                                  neighbour_m=30.0)
    front = facade_class_mask(render_facade(K, pose, length_m=L_M, height_m=H_M, windows=[])[0])
    central = np.zeros_like(front)
    central[64:192, 64:192] = True
    assert (facade_class_mask(labels) & ~front & central).sum() > (front & central).sum()
    target_normal = pose[:3, :3].T @ [0.0, -1.0, 0.0]
    rng = np.random.default_rng(0)
    mask, plane = isolate_facade_on_plane(labels, depth, K, PlaneIsolationConfig(), rng)
    np.testing.assert_allclose(plane.normal, target_normal, atol=1e-3)
    assert (mask & ~front).sum() <= front.any(axis=1).sum()
    # Without the anchor (every wall pixel may seed), RANSAC takes the neighbour.
    _, free = isolate_facade_on_plane(labels, depth, K, PlaneIsolationConfig(
        anchor_points=10**6), np.random.default_rng(0))
    assert not np.allclose(free.normal, target_normal, atol=1e-3)


def test_occluders_bridge_the_2ds_component():
    labels = np.zeros((30, 20), np.uint8)
    labels[2:10] = 1  # wall strip above ...
    labels[10:14] = 5  # ... a balcony band (other) ...
    labels[14:28] = 1  # ... and the wall strip around the image centre
    labels[5:7, 5:8] = 2  # a window in the top strip
    mask = isolate_facade_2ds(labels)
    assert mask.sum() == 8 * 20 + 14 * 20 and not mask[10:14].any()
    labels[10:14] = 0  # background instead: the strips are separate facades
    assert isolate_facade_2ds(labels).sum() == 14 * 20


def test_wall_tolerance_grows_to_one_relative_depth_step():
    labels = np.full((4, 4), SemanticClass.WALL, np.uint8)
    config = PlaneIsolationConfig()
    far = tolerance_for_depth_steps(config, labels, np.full((4, 4), 40.0), 1 / 128)
    assert far.wall_tolerance_m == pytest.approx(40.0 / 128)
    assert tolerance_for_depth_steps(config, labels, np.full((4, 4), 2.0), 1 / 128) == config
    assert tolerance_for_depth_steps(config, labels, np.full((4, 4), 40.0), 0.0) == config
