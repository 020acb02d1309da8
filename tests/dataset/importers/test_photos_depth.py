"""dataset.importers.photos.sparse_depth and photo_depth: a photo's depth from the sparse
points it observes, in closed form. Points on a plane give that plane's depth at every
pixel inside their hull (1e-9 m); a near and a far wall are not bridged; a COLMAP text
project with tracks gets depth images that agree with ray casting to the PNG's millimetre."""

from __future__ import annotations

import json

import numpy as np
import pytest
from PIL import Image
from scipy.spatial import Delaunay
from scipy.spatial.transform import Rotation

from dataset.generate import main as generate_main
from dataset.importers.photos.conventions import cam_from_world_cv
from dataset.importers.photos.photo_depth import depth_unit_m
from dataset.importers.photos.sparse_depth import SparseDepthConfig, piecewise_planar_depth_z_m
from envelope.camera import Intrinsics, look_at, pixel_centres, project_world_to_image, rays_world
from envelope.scenes.scene import read_method_input
from envelope.scenes.scene_validation import read_frame_depth_m

EXACT_M = 1e-9
K = Intrinsics.from_fov(160, 120, 60.0)
PNG_ROUNDING_M = 0.5e-3 + 1e-5
"""Half the PNG's millimetre, and float32 reading it back."""
WALL_Y_M = 0.0
"""The wall: the plane y = 0, x in [-8, 8], z in [0, 9], seen from y < 0."""


def _wall_points(n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.column_stack([rng.uniform(-8, 8, n), np.full(n, WALL_Y_M), rng.uniform(0, 9, n)])


def _plane_depth_z_m(k: Intrinsics, pose: np.ndarray, axis: int, value: float) -> np.ndarray:
    """(H, W) z-depth of the plane ``x[axis] = value`` along every pixel centre's ray."""
    origin, direction = rays_world(k, pose)
    t = (value - origin[..., axis]) / direction[..., axis]
    _, z_m = project_world_to_image(origin + t[..., None] * direction, k, pose)
    return z_m


def _inside_hull(uv: np.ndarray, k: Intrinsics, tolerance: float = -1e-7) -> np.ndarray:
    """(H, W) bool: pixel centres inside the hull of (N, 2) image points (at least
    ``-tolerance`` inside it in barycentric terms; a positive ``tolerance`` takes those
    that near outside too)."""
    hull = Delaunay(uv)
    return hull.find_simplex(pixel_centres(k).reshape(-1, 2), tol=tolerance).reshape(
        k.height, k.width) >= 0


@pytest.mark.parametrize("eye", [[0.0, -15.0, 2.0], [9.0, -9.0, 6.0]])
def test_points_on_a_plane_give_its_depth_everywhere_inside_their_hull(eye):
    pose = look_at(eye, [0.0, 0.0, 4.0])
    points = _wall_points(300)
    depth = piecewise_planar_depth_z_m(points, K, pose)
    truth = _plane_depth_z_m(K, pose, 1, WALL_Y_M)
    uv, _ = project_world_to_image(points, K, pose)
    inside = _inside_hull(uv, K)
    assert inside.mean() > 0.3  # the check covers much of the image
    assert (depth[inside] > 0).all()
    assert np.abs(depth[depth > 0] - truth[depth > 0]).max() < EXACT_M
    assert not depth[~_inside_hull(uv, K, tolerance=1e-7)].any()


def test_a_near_and_a_far_wall_are_not_bridged():
    """A wall 10 m off on the image's left half and one 40 m off on its right, points on a
    regular grid of about 8 px over the whole image: the triangles joining them are seen
    edge-on and left out; all else has the depth of its wall."""
    pose = look_at([0.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    u, v = np.meshgrid(np.linspace(0.5, 159.5, 21), np.linspace(0.5, 119.5, 16))
    uv = np.column_stack([u.ravel(), v.ravel()])
    z_m = np.where(uv[:, 0] < 80, 10.0, 40.0)
    # Camera looking along +y from the origin: image x is world x, image down is world -z.
    points = np.column_stack([(uv[:, 0] - K.cx) / K.fx * z_m, z_m,
                              -(uv[:, 1] - K.cy) / K.fy * z_m])
    depth = piecewise_planar_depth_z_m(points, K, pose)
    on_a_wall = (np.abs(depth - 10.0) < EXACT_M) | (np.abs(depth - 40.0) < EXACT_M)
    assert (on_a_wall | (depth == 0)).all()
    assert (np.abs(depth[:, :72] - 10.0) < EXACT_M).all()
    assert (np.abs(depth[:, 88:] - 40.0) < EXACT_M).all()
    # With no limit on the incidence, the gap is bridged by slanted triangles.
    bridged = piecewise_planar_depth_z_m(points, K, pose, SparseDepthConfig(90.0))
    assert ((bridged > 10.0 + 1e-6) & (bridged < 40.0 - 1e-6)).any()


def test_too_few_points_give_no_depth_and_bad_points_are_refused():
    pose = look_at([0.0, -15.0, 2.0], [0.0, 0.0, 4.0])
    behind = _wall_points(50) + [0.0, -30.0, 0.0]  # behind the camera
    assert not piecewise_planar_depth_z_m(behind, K, pose).any()
    line = np.column_stack([np.linspace(-5, 5, 9), np.zeros(9), np.full(9, 4.0)])
    assert not piecewise_planar_depth_z_m(line, K, pose).any()  # one image line: no triangle
    assert not piecewise_planar_depth_z_m(_wall_points(2), K, pose).any()
    with pytest.raises(ValueError, match="finite"):
        piecewise_planar_depth_z_m(np.array([[0.0, 0.0, np.nan]] * 3), K, pose)
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        piecewise_planar_depth_z_m(np.zeros((4, 2)), K, pose)
    with pytest.raises(ValueError, match="max_incidence_deg"):
        SparseDepthConfig(0.0)


def test_the_depth_unit_is_a_millimetre_unless_the_scene_is_deeper_than_16_bits_hold():
    assert depth_unit_m(65.535) == 0.001
    assert depth_unit_m(65.6) == pytest.approx(0.002)
    assert depth_unit_m(300.0) == pytest.approx(0.005)


TURN = Rotation.from_euler("xyz", [30, -50, 110], degrees=True).as_matrix()
SHRINK = 0.25
SHIFT = np.array([1.0, -2.0, 0.5])


def _moved(pose: np.ndarray) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = TURN @ pose[:3, :3]
    out[:3, 3] = SHRINK * TURN @ pose[:3, 3] + SHIFT
    return out


def test_a_colmap_project_gets_the_depth_its_tracks_measure(tmp_path, capsys):
    """Six cameras before the wall in a turned, shrunk and shifted frame; camera 2 has
    radial distortion (undistorted, cropped: other intrinsics), image 4 observes no point.
    Each depth image matches ray casting the wall with the frame's own intrinsics to the
    PNG's millimetre, everywhere inside the hull of the points the image observes."""
    project = tmp_path / "survey"
    (project / "sparse" / "0").mkdir(parents=True)
    (project / "images").mkdir()
    poses = [look_at([x, -14.0 - (i % 2), 1.5 + i % 3], [0.3 * x, 0.0, 4.0])
             for i, x in enumerate(np.linspace(-6, 6, 6))]
    cameras = [f"1 PINHOLE {K.width} {K.height} {K.fx} {K.fy} {K.cx} {K.cy}",
               f"2 SIMPLE_RADIAL {K.width} {K.height} {K.fx} {K.cx} {K.cy} 0.08"]
    points = _wall_points(400)
    tracks: list[list[str]] = [[] for _ in points]
    images = []
    rng = np.random.default_rng(1)
    for i, pose in enumerate(poses):
        cv = cam_from_world_cv(_moved(pose))
        x, y, z, w = Rotation.from_matrix(cv[:3, :3]).as_quat()
        camera = 1 + (i == 5)
        uv, z_m = project_world_to_image(points, K, pose)
        seen = np.flatnonzero((z_m > 0) & (uv[:, 0] > 0) & (uv[:, 0] < K.width) & (uv[:, 1] > 0)
                              & (uv[:, 1] < K.height) & (rng.random(len(points)) < 0.7))
        if i == 4:
            seen = seen[:0]
        for idx, j in enumerate(seen):
            tracks[j] += [str(i + 1), str(idx)]
        images += [f"{i + 1} {w} {x} {y} {z} {' '.join(map(str, cv[:, 3]))} {camera} p{i}.png",
                   " ".join(f"{uv[j, 0]} {uv[j, 1]} {j + 1}" for j in seen)]
        rgb = rng.integers(0, 255, (K.height, K.width, 3), np.uint8)
        Image.fromarray(rgb).save(project / "images" / f"p{i}.png")
    moved = SHRINK * points @ TURN.T + SHIFT
    (project / "sparse" / "0" / "cameras.txt").write_text("\n".join(cameras) + "\n")
    (project / "sparse" / "0" / "images.txt").write_text("\n".join(images) + "\n")
    (project / "sparse" / "0" / "points3D.txt").write_text("".join(
        f"{j + 1} {p[0]} {p[1]} {p[2]} 128 128 128 0.5 {' '.join(tracks[j])}\n"
        for j, p in enumerate(moved)))
    distance = np.linalg.norm(poses[0][:3, 3] - poses[5][:3, 3])
    code = generate_main(["--photos", str(project), "--out", str(tmp_path / "out"),
                          "--known-distance", "p0.png", "p5.png", str(distance), "--quiet"])
    assert code == 0, capsys.readouterr().err
    scene = read_method_input(tmp_path / "out" / "survey")
    record = json.loads((tmp_path / "out" / "survey" / "transforms.json").read_text())
    assert record["photos"]["depth"]["photos_with_depth"] == 5
    assert scene.depth_unit_scale_factor == 0.001
    for i, (frame, pose) in enumerate(zip(scene.frames, poses)):
        if i == 4:
            assert frame.depth_file_path is None
            continue
        k = frame.intrinsics
        assert (k == K) == (i != 5)
        depth = read_frame_depth_m(scene, frame)
        # The scene's pose is the true one turned about z and shifted: depth is the same.
        truth = _plane_depth_z_m(k, pose, 1, WALL_Y_M)
        uv, _ = project_world_to_image(
            points[[j for j, t in enumerate(tracks) if str(i + 1) in t[::2]]], k, pose)
        inside = _inside_hull(uv, k)
        assert (depth[inside] > 0).all()
        assert np.abs(depth[depth > 0] - truth[depth > 0]).max() <= PNG_ROUNDING_M
