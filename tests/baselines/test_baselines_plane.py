"""baselines.plane: least-squares and RANSAC planes, ray-plane intersection (closed forms)."""

import numpy as np
import pytest

from baselines.plane import (
    fit_plane_ransac,
    intersect_rays_plane,
    plane_through_points,
    points_camera_m,
)
from envelope.camera import Intrinsics


def _plane_points(rng, n):
    # The plane z = -10 + 0.5 x (in the camera frame, in front of the camera).
    x, y = rng.uniform(-5, 5, (2, n))
    return np.stack([x, y, -10 + 0.5 * x], axis=-1)


def test_plane_through_points_is_exact_and_faces_the_camera():
    p = _plane_points(np.random.default_rng(0), 50)
    plane = plane_through_points(p)
    np.testing.assert_allclose(plane.signed_distance_m(p), 0, atol=1e-12)
    expected = np.array([-0.5, 0, 1]) / np.sqrt(1.25)
    np.testing.assert_allclose(plane.normal, expected, atol=1e-12)
    assert plane.signed_distance_m(np.zeros(3)) > 0  # camera on the positive side
    assert plane.signed_distance_m(np.array([0, 0, -20.0])) < 0


def test_ransac_ignores_outliers():
    rng = np.random.default_rng(1)
    p = _plane_points(rng, 300)
    outliers = rng.uniform([-5, -5, -30], [5, 5, -2], (150, 3))
    plane = fit_plane_ransac(np.concatenate([p, outliers]), threshold_m=0.01, iterations=64,
                             rng=rng)
    np.testing.assert_allclose(plane.signed_distance_m(p), 0, atol=1e-9)


def test_rays_meet_the_plane_at_the_points_they_came_from():
    k = Intrinsics.from_fov(64, 48, 60.0)
    rng = np.random.default_rng(2)
    uv = rng.uniform([0, 0], [64, 48], (20, 2))
    depth = 8 + 2 * rng.uniform(size=20)
    p = points_camera_m(uv, depth, k)
    np.testing.assert_allclose(-p[:, 2], depth)  # z-depth along -z
    plane = plane_through_points(p[:3])
    hit = intersect_rays_plane(uv[:3], plane, k)
    np.testing.assert_allclose(hit, p[:3], atol=1e-9)


def test_bad_inputs_say_what_is_wrong():
    with pytest.raises(ValueError, match="at least 3 points"):
        plane_through_points(np.zeros((2, 3)))
    with pytest.raises(ValueError, match="collinear"):
        plane_through_points(np.array([[0, 0, -1.0], [1, 0, -1], [2, 0, -1]]))
    with pytest.raises(ValueError, match="threshold_m"):
        fit_plane_ransac(np.eye(3), threshold_m=0, iterations=3, rng=np.random.default_rng())
    k = Intrinsics.from_fov(64, 48, 60.0)
    edge_on = plane_through_points(np.array([[1.0, 0, 0], [1, 1, -1], [1, 0, -5]]))  # x = 1
    with pytest.raises(ValueError, match="edge-on"):
        intersect_rays_plane(np.array([[32.0, 24.0]]), edge_on, k)


def test_anchored_ransac_finds_the_smaller_plane_through_the_anchors():
    rng = np.random.default_rng(3)
    small = _plane_points(rng, 100)  # z = -10 + 0.5 x
    x, y = rng.uniform(-5, 5, (2, 400))
    big = np.stack([x, y, -14 - 0.5 * x], axis=-1)  # another plane, four times the support
    pts = np.concatenate([small, big])
    free = fit_plane_ransac(pts, threshold_m=0.01, iterations=64, rng=rng)
    np.testing.assert_allclose(free.signed_distance_m(big), 0, atol=1e-9)
    anchored = fit_plane_ransac(pts, threshold_m=0.01, iterations=64, rng=rng,
                                anchor_points_m=small[:5])
    np.testing.assert_allclose(anchored.signed_distance_m(small), 0, atol=1e-9)
