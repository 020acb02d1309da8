"""dataset.importers.photos: inputs already posed are taken as they are. A COLMAP project
(text model) and a nerfstudio ``transforms.json`` of known cameras, in a turned, shrunk and
shifted frame, come out in metres with z up: the known cameras up to a turn about z."""

from __future__ import annotations

import json

import numpy as np
import pytest
from PIL import ExifTags, Image
from scipy.spatial.transform import Rotation

from dataset.generate import main as generate_main
from dataset.importers.photos.conventions import cam_from_world_cv
from envelope.camera import Intrinsics, look_at
from envelope.scenes.scene import read_method_input

EXACT = 1e-9
K = Intrinsics(90.0, 90.0, 48.0, 32.0, 96, 64)
TURN = Rotation.from_euler("xyz", [30, -50, 110], degrees=True).as_matrix()
SHRINK = 0.25
SHIFT = np.array([1.0, -2.0, 0.5])
HEIGHTS = np.linspace(0.0, 9.0, 2001)  # the sparse points' heights: ground to a 9 m top


def _true_poses() -> np.ndarray:
    return np.stack([look_at([20 * np.cos(a), 20 * np.sin(a), 1.5 + (i % 3)], [0, 0, 3])
                     for i, a in enumerate(np.linspace(0, 2 * np.pi, 6, endpoint=False))])


def _moved(pose: np.ndarray) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = TURN @ pose[:3, :3]
    out[:3, 3] = SHRINK * TURN @ pose[:3, 3] + SHIFT
    return out


def _image(path, width: int, height: int, exif: Image.Exif | None = None) -> None:
    rgb = np.random.default_rng(len(path.name)).integers(0, 255, (height, width, 3), np.uint8)
    Image.fromarray(rgb).save(path, **({"exif": exif} if exif is not None else {}))


def _check_metric(scene_dir, truth: np.ndarray, ground_m: float | None) -> np.ndarray:
    """The scene's poses are ``truth`` turned about z (and shifted by ``ground_m`` down, or
    horizontally anywhere when ``None``); return them."""
    scene = read_method_input(scene_dir)
    out = np.stack([f.world_from_camera for f in scene.frames])
    pairwise = np.linalg.norm(out[:, None, :3, 3] - out[None, :, :3, 3], axis=-1)
    true_pairwise = np.linalg.norm(truth[:, None, :3, 3] - truth[None, :, :3, 3], axis=-1)
    assert np.abs(pairwise - true_pairwise).max() < 1e-9
    assert np.abs(out[:, :3, :3].transpose(0, 2, 1)[:, :, 2]
                  - truth[:, :3, :3].transpose(0, 2, 1)[:, :, 2]).max() < EXACT
    if ground_m is not None:
        assert np.abs(out[:, 2, 3] - (truth[:, 2, 3] - ground_m)).max() < 1e-9
    return out


def test_a_colmap_project_is_taken_as_it_is_and_read_as_stored(tmp_path, capsys):
    project = tmp_path / "survey"
    (project / "sparse" / "0").mkdir(parents=True)
    (project / "images").mkdir()
    truth = _true_poses()
    sideways = Image.Exif()
    sideways[ExifTags.Base.Orientation] = 6  # COLMAP reads the pixels as stored: so do we
    cameras = [f"1 PINHOLE {K.width} {K.height} {K.fx} {K.fy} {K.cx} {K.cy}",
               f"2 SIMPLE_RADIAL {K.width} {K.height} {K.fx} {K.cx} {K.cy} 0.08"]
    images = []
    for i, pose in enumerate(truth):
        cv = cam_from_world_cv(_moved(pose))
        x, y, z, w = Rotation.from_matrix(cv[:3, :3]).as_quat()
        camera = 1 + (i == 5)
        images += [f"{i + 1} {w} {x} {y} {z} {' '.join(map(str, cv[:, 3]))} {camera} p{i}.jpg",
                   ""]
        _image(project / "images" / f"p{i}.jpg", K.width, K.height, sideways)
    rng = np.random.default_rng(0)
    points = np.column_stack([rng.uniform(-5, 5, HEIGHTS.size), rng.uniform(-4, 4, HEIGHTS.size),
                              HEIGHTS])
    moved_points = SHRINK * points @ TURN.T + SHIFT
    (project / "sparse" / "0" / "cameras.txt").write_text("\n".join(cameras) + "\n")
    (project / "sparse" / "0" / "images.txt").write_text("\n".join(images) + "\n")
    (project / "sparse" / "0" / "points3D.txt").write_text("".join(
        f"{j + 1} {p[0]} {p[1]} {p[2]} 128 128 128 0.5\n" for j, p in enumerate(moved_points)))
    code = generate_main(["--photos", str(project), "--out", str(tmp_path / "out"),
                          "--known-height", str(9.0 * 0.98), "--quiet"])
    assert code == 0, capsys.readouterr().err
    # The points' 1st to 99th percentile span 0.98 x 9 m; the ground goes to their 1st.
    _check_metric(tmp_path / "out" / "survey", truth, ground_m=np.percentile(HEIGHTS, 1))
    meta = json.loads((tmp_path / "out" / "survey" / "transforms.json").read_text())
    assert meta["photos"]["input"] == "COLMAP model"
    # Its poses are given: the record times reading, the metric frame, writing and the
    # depth from its points alone.
    for seconds in meta["photos"]["seconds"], meta["photos"]["cpu_seconds"]:
        assert list(seconds) == ["reading", "metric_frame", "writing", "depth", "total"]
        assert min(seconds.values()) >= 0
        assert abs(seconds["total"] - sum(v for k, v in seconds.items() if k != "total")) <= 0.02
    sizes = {f["file_path"]: (f.get("w", meta["w"]), f.get("h", meta["h"]))
             for f in meta["frames"]}
    assert sizes["images/p0.jpg"] == (K.width, K.height)  # stored size, not turned
    assert sizes["images/p5.jpg"] != (K.width, K.height)  # undistorted: cropped to valid


@pytest.mark.parametrize("k1", [0.0, 0.05])
def test_a_nerfstudio_file_keeps_its_origin_and_is_undistorted(tmp_path, capsys, k1):
    folder = tmp_path / "capture"
    (folder / "images").mkdir(parents=True)
    truth = _true_poses()
    frames = []
    for i, pose in enumerate(truth):
        _image(folder / "images" / f"f{i}.png", K.width, K.height)
        frames.append({"file_path": f"images/f{i}.png",
                       "transform_matrix": _moved(pose)[:3].tolist()})
    (folder / "transforms.json").write_text(json.dumps({
        "camera_model": "OPENCV", "fl_x": K.fx, "fl_y": K.fy, "cx": K.cx, "cy": K.cy,
        "w": K.width, "h": K.height, "k1": k1, "frames": frames}))
    distance = np.linalg.norm(truth[0, :3, 3] - truth[3, :3, 3])
    code = generate_main(["--photos", str(folder / "transforms.json"), "--out",
                          str(tmp_path / "out"), "--known-distance", "f0.png", "f3.png",
                          str(distance), "--quiet"])
    assert code == 0, capsys.readouterr().err
    out = _check_metric(tmp_path / "out" / "capture", truth, ground_m=None)
    # No points: the input's origin stays, so the shift is the input's, turned and scaled.
    origin = np.linalg.solve(TURN, -SHIFT) / SHRINK  # the true world's point at the input origin
    turn_z = out[0, :3, :3] @ truth[0, :3, :3].T
    assert np.abs(out[:, :3, 3] - (truth[:, :3, 3] - origin) @ turn_z.T).max() < 1e-9
    scene = read_method_input(tmp_path / "out" / "capture")
    assert (scene.frames[0].intrinsics == K) == (k1 == 0.0)
    # A nerfstudio file has no points: no depth.
    assert all(f.depth_file_path is None for f in scene.frames)
    assert not (tmp_path / "out" / "capture" / "depth").exists()
