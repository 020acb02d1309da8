"""baselines.backproject: corner rays on the facade plane, facade length and height."""

import numpy as np
import pytest

from baselines.backproject import (
    corner_angles_deg,
    corners_camera_m,
    facade_size_m,
    image_from_camera_uv,
    upright_rectangle_m,
)
from baselines.plane import Plane, plane_through_points
from baselines.views import ViewError
from envelope.camera import Intrinsics, look_at, project_world_to_image


def test_size_of_a_rectangle_in_any_frame():
    rect = np.array([[0, 0, 9], [12, 0, 9], [12, 0, 0], [0, 0, 0.0]])  # TL TR BR BL
    assert facade_size_m(rect) == pytest.approx((12.0, 9.0))
    r = np.linalg.qr(np.random.default_rng(0).normal(size=(3, 3)))[0]
    assert facade_size_m(rect @ r.T + [3, -2, 7]) == pytest.approx((12.0, 9.0))


def test_corner_rays_recover_the_3d_corners_even_on_background_pixels():
    # A facade 12 m x 9 m in the plane y = 0 seen obliquely; the corners are
    # found only from their image position and the plane, never from depth.
    k = Intrinsics.from_fov(320, 240, 60.0)
    pose = look_at([14.0, -13.0, 1.6], [6.0, 0.0, 4.5])
    world = np.array([[0, 0, 9], [12, 0, 9], [12, 0, 0], [0, 0, 0.0]])
    uv, _ = project_world_to_image(world, k, pose)
    camera_from_world = np.linalg.inv(pose)
    cam = world @ camera_from_world[:3, :3].T + camera_from_world[:3, 3]
    plane = plane_through_points(cam[:3])
    np.testing.assert_allclose(corners_camera_m(uv, plane, k), cam, atol=1e-9)
    assert facade_size_m(corners_camera_m(uv, plane, k)) == pytest.approx((12.0, 9.0))


def test_edge_on_plane_and_bad_shapes_are_refused():
    k = Intrinsics.from_fov(64, 48, 60.0)
    edge_on = Plane(np.array([1.0, 0.0, 0.0]), -1.0)  # x = -1, parallel to the optical axis
    corners = np.array([[32.0, 24], [33, 24], [33, 25], [32, 25]])
    with pytest.raises(ViewError, match="edge-on"):
        corners_camera_m(corners, edge_on, k)
    with pytest.raises(ValueError, match=r"\(4, 2\)"):
        corners_camera_m(corners[:3], edge_on, k)
    with pytest.raises(ViewError, match="degenerate"):
        facade_size_m(np.zeros((4, 3)))


def test_corner_angles_of_a_rectangle_and_a_trapezoid():
    rect = np.array([[0, 9, 0], [12, 9, 0], [12, 0, 0], [0, 0, 0.0]])
    np.testing.assert_allclose(corner_angles_deg(rect), 90.0)
    trapezoid = np.array([[3, 3, 0], [6, 3, 0], [9, 0, 0], [0, 0, 0.0]])
    np.testing.assert_allclose(corner_angles_deg(trapezoid), [135, 135, 45, 45])


def test_upright_rectangle_encloses_a_gable_facade():
    # Pentagon 10 m wide, eaves at 6 m, ridge at 9 m, in the plane y = 0, seen
    # obliquely; its outline's bounding rectangle is 10 m x 9 m, upright.
    k = Intrinsics.from_fov(320, 240, 60.0)
    pose = look_at([12.0, -14.0, 1.6], [5.0, 0.0, 4.5])
    s = np.linspace(0, 1, 200)[:, None]
    outline = np.concatenate([
        [0, 0, 0] + s * [10, 0, 0], [10, 0, 0] + s * [0, 0, 6], [10, 0, 6] + s * [-5, 0, 3],
        [5, 0, 9] + s * [-5, 0, -3], [0, 0, 6] + s * [0, 0, -6]])
    uv, _ = project_world_to_image(outline, k, pose)
    camera_from_world = np.linalg.inv(pose)
    cam = outline @ camera_from_world[:3, :3].T + camera_from_world[:3, 3]
    plane = plane_through_points(cam[[0, 250, 600]])
    up_camera = pose[:3, :3].T @ [0, 0, 1.0]
    corners = upright_rectangle_m(uv, plane, k, up_camera)
    # Half-pixel squares around each outline point: within a few cm at this range.
    length, height = facade_size_m(corners)
    assert length == pytest.approx(10.0, abs=0.1) and height == pytest.approx(9.0, abs=0.1)
    np.testing.assert_allclose(corner_angles_deg(corners), 90.0, atol=1e-9)
    world = corners @ pose[:3, :3].T + pose[:3, 3]
    np.testing.assert_allclose(world[[0, 1], 2], 9.0, atol=0.1)  # the top edge is level
    uv_back = image_from_camera_uv(corners, k)
    assert uv_back[0, 0] < uv_back[1, 0] and uv_back[0, 1] < uv_back[3, 1]  # TL is top-left
    with pytest.raises(ViewError, match="horizontal"):
        upright_rectangle_m(uv, plane, k, plane.normal)
