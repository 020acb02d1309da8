"""dataset.importers.photos: COLMAP's poses in the project's convention, and the metric frame
(up, scale, origin), against closed-form answers."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from dataset.importers.photos.conventions import cam_from_world_cv, world_from_camera_gl
from dataset.importers.photos.metric_frame import (
    GROUND_PERCENTILE,
    KnownDistance,
    ScaleHint,
    metric_similarity,
    up_from_cameras,
)
from envelope.camera import Intrinsics, look_at, project_world_to_image

EXACT = 1e-9


def _orbit(n: int, radius_m: float, heights_m: tuple[float, ...]) -> np.ndarray:
    """(n, 4, 4) level-roll cameras round the origin, looking at a point 3 m up."""
    return np.stack([look_at([radius_m * np.cos(a), radius_m * np.sin(a),
                              heights_m[i % len(heights_m)]], [0.0, 0.0, 3.0])
                     for i, a in enumerate(np.linspace(0, 2 * np.pi, n, endpoint=False))])


def _opencv_project(cam_from_world: np.ndarray, k: Intrinsics, points: np.ndarray) -> np.ndarray:
    """COLMAP's projection: x_cam = R p + t, (u, v) = K x_cam / z_cam (z forward, y down)."""
    cam = points @ cam_from_world[:3, :3].T + cam_from_world[:3, 3]
    uvw = cam @ k.K.T
    return uvw[:, :2] / uvw[:, 2:]


def test_colmap_poses_round_trip_and_project_as_the_project_does():
    rng = np.random.default_rng(3)
    k = Intrinsics(500.0, 480.0, 320.5, 240.25, 640, 480)
    points = rng.uniform(-5, 5, (50, 3))
    for _ in range(10):
        pose = look_at(rng.uniform(10, 20, 3) * rng.choice([-1, 1], 3), rng.uniform(-1, 1, 3))
        cv = cam_from_world_cv(pose)
        assert np.abs(world_from_camera_gl(cv) - pose).max() < EXACT
        assert np.abs(world_from_camera_gl(np.vstack([cv, [0, 0, 0, 1]])) - pose).max() < EXACT
        uv_ours, depth = project_world_to_image(points, k, pose)
        # The same pixel in both conventions (both put pixel centres at +0.5).
        assert np.abs(_opencv_project(cv, k, points) - uv_ours).max() < 1e-6
        assert np.allclose(depth, (points @ cv[:3, :3].T + cv[:3, 3])[:, 2])


def test_a_bad_pose_shape_is_refused():
    with pytest.raises(ValueError, match="3x4 or 4x4"):
        world_from_camera_gl(np.eye(3))


@pytest.mark.parametrize("seed", range(3))
def test_up_is_exact_for_cameras_without_roll_whatever_their_pitch(seed):
    turn = Rotation.random(random_state=seed).as_matrix()
    poses = _orbit(12, 20.0, (1.0, 9.0, 25.0))  # pitch from about -6 to +54 degrees
    turned = np.einsum("ij,njk->nik", np.block([[turn, np.zeros((3, 1))],
                                                [np.zeros((1, 3)), np.ones((1, 1))]]), poses)
    up, how = up_from_cameras(turned)
    assert np.abs(up - turn[:, 2]).max() < EXACT
    assert "x axes" in how


def test_photos_facing_one_way_take_the_mean_camera_up():
    poses = np.stack([look_at([x, -20.0, 1.6], [x, 0.0, 1.6]) for x in np.linspace(-8, 8, 5)])
    up, how = up_from_cameras(poses)
    assert np.abs(up - [0.0, 0.0, 1.0]).max() < EXACT
    assert "one way" in how


def _similarity_inputs(seed: int):
    """A turned, shrunk and shifted copy of a metric scene: poses, points and the similarity
    (scale, rotation) that made it."""
    rng = np.random.default_rng(seed)
    turn = Rotation.random(random_state=seed).as_matrix()
    shrink = 0.137
    shift = rng.uniform(-3, 3, 3)
    poses = _orbit(8, 20.0, (2.0, 6.0))
    # A building 9 m high: points from the ground to the top, uniform in height.
    points = np.column_stack([rng.uniform(-5, 5, 2001), rng.uniform(-4, 4, 2001),
                              np.linspace(0.0, 9.0, 2001)])
    moved = poses.copy()
    moved[:, :3, :3] = turn @ poses[:, :3, :3]
    moved[:, :3, 3] = shrink * poses[:, :3, 3] @ turn.T + shift
    return poses, moved, shrink * points @ turn.T + shift, shrink


def test_a_known_distance_gives_metres_and_z_up():
    poses, moved, _points, shrink = _similarity_inputs(0)
    names = [f"p{i}.jpg" for i in range(len(poses))]
    true_distance = np.linalg.norm(poses[0, :3, 3] - poses[4, :3, 3])
    similarity, record = metric_similarity(
        moved, names, None, ScaleHint(KnownDistance("p0.jpg", "p4.jpg", true_distance)))
    assert similarity.scale == pytest.approx(1 / shrink, rel=1e-12)
    out = np.stack([similarity.pose(p) for p in moved])
    # Metres and z up: heights and distances as in the metric scene, up to a turn about z.
    assert np.abs(out[:, 2, 3] - out[0, 2, 3] - (poses[:, 2, 3] - poses[0, 2, 3])).max() < 1e-9
    assert np.abs(out[:, :3, 1] @ [0, 0, 1] - poses[:, :3, 1] @ [0, 0, 1]).max() < EXACT
    pairwise = np.linalg.norm(out[:, None, :3, 3] - out[None, :, :3, 3], axis=-1)
    truth = np.linalg.norm(poses[:, None, :3, 3] - poses[None, :, :3, 3], axis=-1)
    assert np.abs(pairwise - truth).max() < 1e-9
    # North: +y is the way the first photo looks, level.
    forward = -out[0, :3, 2]
    assert np.abs(forward[:2] / np.linalg.norm(forward[:2]) - [0, 1]).max() < EXACT
    assert "known distance" in record["scale"]


def test_a_known_height_gives_the_scale_and_puts_the_ground_at_zero():
    poses, moved, points, shrink = _similarity_inputs(1)
    names = [f"p{i}.jpg" for i in range(len(poses))]
    similarity, record = metric_similarity(moved, names, points, ScaleHint(known_height_m=9.0))
    # The span between the percentiles of heights uniform on [0, 9] is 9 * (99 - 1) / 100.
    assert similarity.scale == pytest.approx(1 / shrink / 0.98, rel=1e-3)
    ground = similarity.points(points)[:, 2]
    assert np.percentile(ground, GROUND_PERCENTILE) == pytest.approx(0.0, abs=1e-9)
    assert "known building height" in record["scale"]


@pytest.mark.parametrize(("hint", "message"), [
    (dict(), "no scale: say what you know, with --known-distance"),
    (dict(known_height_m=10.0, known_distance=KnownDistance("a", "b", 2.0)), "one scale"),
    (dict(known_height_m=-1.0), "positive number"),
    (dict(known_distance=KnownDistance("a", "a", 2.0)), "two different photos"),
])
def test_a_scale_hint_is_one_positive_measure(hint, message):
    with pytest.raises(ValueError, match=message):
        ScaleHint(**hint)


def test_a_known_distance_to_an_unposed_photo_or_a_height_without_points_is_refused():
    _, moved, _, _ = _similarity_inputs(2)
    names = [f"p{i}.jpg" for i in range(len(moved))]
    with pytest.raises(ValueError, match="names lost.jpg, which has no camera pose"):
        metric_similarity(moved, names, None, ScaleHint(KnownDistance("p0.jpg", "lost.jpg", 3)))
    with pytest.raises(ValueError, match="--known-height needs the sparse points"):
        metric_similarity(moved, names, None, ScaleHint(known_height_m=9.0))
