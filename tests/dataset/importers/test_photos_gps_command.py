"""``python -m dataset.generate --photos ... --gps``: a COLMAP project and a folder of photos
with EXIF GPS come out north-up, each refusal leaves nothing written, and (slow) structure
from motion of a textured block whose photos carry noisy GPS positions."""

from __future__ import annotations

import json
import math
import re

import cv2
import numpy as np
import pytest
from photos_gps_cases import ORIGIN, SHIFT, SHRINK, TURN, K, gps_exif, moved_pose, true_poses
from PIL import Image
from scipy.spatial.transform import Rotation

from dataset.generate import main as generate_main
from dataset.importers.photos.conventions import cam_from_world_cv
from dataset.importers.photos.gps import wgs84_from_east_north
from dataset.importers.photos.gps_fit import OUTLIER_M, similarity_2d
from envelope.scenes.scene import read_method_input

# --- end to end --------------------------------------------------------------------------

def _colmap_project_with_gps(root, truth: np.ndarray, fixes: list[tuple[float, float] | None]):
    """A COLMAP text project of ``truth`` moved by TURN, SHRINK and SHIFT, its images
    carrying the given GPS positions (latitude, longitude; ``None``: no GPS)."""
    (root / "sparse" / "0").mkdir(parents=True)
    (root / "images").mkdir()
    images = []
    for i, pose in enumerate(truth):
        cv = cam_from_world_cv(moved_pose(pose))
        x, y, z, w = Rotation.from_matrix(cv[:3, :3]).as_quat()
        images += [f"{i + 1} {w} {x} {y} {z} {' '.join(map(str, cv[:, 3]))} 1 p{i}.jpg", ""]
        rgb = np.random.default_rng(i).integers(0, 255, (K.height, K.width, 3), np.uint8)
        exif = gps_exif(*fixes[i]) if fixes[i] is not None else None
        Image.fromarray(rgb).save(root / "images" / f"p{i}.jpg",
                                  **({"exif": exif} if exif is not None else {}))
    rng = np.random.default_rng(0)
    points = np.column_stack([rng.uniform(-5, 5, 500), rng.uniform(-4, 4, 500),
                              np.linspace(0.0, 9.0, 500)])
    (root / "sparse" / "0" / "cameras.txt").write_text(
        f"1 PINHOLE {K.width} {K.height} {K.fx} {K.fy} {K.cx} {K.cy}\n")
    (root / "sparse" / "0" / "images.txt").write_text("\n".join(images) + "\n")
    (root / "sparse" / "0" / "points3D.txt").write_text("".join(
        f"{j + 1} {p[0]} {p[1]} {p[2]} 128 128 128 0.5\n"
        for j, p in enumerate(SHRINK * points @ TURN.T + SHIFT)))


def test_a_colmap_project_with_gps_photos_comes_out_north_up(tmp_path, capsys):
    truth = true_poses()
    fixes = [tuple(wgs84_from_east_north(p[:2, 3], ORIGIN)[0]) for p in truth]
    _colmap_project_with_gps(tmp_path / "survey", truth, fixes)
    code = generate_main(["--photos", str(tmp_path / "survey"), "--out", str(tmp_path / "out"),
                          "--gps", "--quiet"])
    assert code == 0, capsys.readouterr().err
    scene = read_method_input(tmp_path / "out" / "survey")
    out = np.stack([f.world_from_camera for f in scene.frames])
    assert np.abs(out[:, :3, :3] - truth[:, :3, :3]).max() < 1e-6  # +y north, x east
    shift = out[0, :3, 3] - truth[0, :3, 3]
    assert np.abs(out[:, :3, 3] - truth[:, :3, 3] - shift).max() < 1e-5
    record = json.loads((tmp_path / "out" / "survey" / "transforms.json").read_text())["photos"]
    assert record["scale_source"] == "gps" and record["north_known"] is True
    assert record["gps"]["fixes_kept"] == 8 and record["gps"]["residual_max_m"] < 1e-5


def test_a_colmap_project_with_too_few_fixes_is_refused_and_leaves_no_scene(tmp_path, capsys):
    truth = true_poses()
    fixes = [tuple(wgs84_from_east_north(p[:2, 3], ORIGIN)[0]) if i < 2 else None
             for i, p in enumerate(truth)]
    _colmap_project_with_gps(tmp_path / "survey", truth, fixes)
    code = generate_main(["--photos", str(tmp_path / "survey"), "--out", str(tmp_path / "out"),
                          "--gps", "--quiet"])
    err = capsys.readouterr().err
    assert code == 2 and "--gps: 2 of 8 photos carry an EXIF GPS position" in err
    assert len(err.strip().splitlines()) == 1
    assert list((tmp_path / "out").iterdir()) == []


def _noise_photos(folder, positions_m: list[np.ndarray | None]) -> None:
    folder.mkdir()
    for i, position in enumerate(positions_m):
        rgb = np.random.default_rng(i).integers(0, 255, (60, 80, 3), np.uint8)
        exif = (gps_exif(*wgs84_from_east_north(position, ORIGIN)[0])
                if position is not None else None)
        Image.fromarray(rgb).save(folder / f"p{i}.jpg",
                                  **({"exif": exif} if exif is not None else {}))


@pytest.mark.parametrize(("positions_m", "message"), [
    ([np.array([0.0, 0.0]), np.array([30.0, 0.0]), None, None],
     "--gps: 2 of 4 photos carry an EXIF GPS position; at least 3"),
    ([np.array([0.0, 0.0]), np.array([10.0, 0.0]), np.array([0.0, 10.0])],
     r"--gps: the photos' GPS positions spread 6\.7 m"),  # RMS about the mean: 20 / 3 m
])
def test_a_photo_folder_without_usable_gps_is_refused_before_anything_runs(
        tmp_path, capsys, positions_m, message):
    _noise_photos(tmp_path / "photos", positions_m)
    code = generate_main(["--photos", str(tmp_path / "photos"), "--out", str(tmp_path / "out"),
                          "--gps", "--quiet"])
    err = capsys.readouterr().err
    assert code == 2 and re.search(message, err), err
    assert len(err.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()


def test_gps_goes_with_photos_and_alone(tmp_path, capsys):
    code = generate_main(["--preset", "tiny", "--out", str(tmp_path / "out"), "--gps"])
    assert code == 2 and "go with --photos" in capsys.readouterr().err
    _noise_photos(tmp_path / "photos", [np.zeros(2)] * 3)
    code = generate_main(["--photos", str(tmp_path / "photos"), "--out", str(tmp_path / "out"),
                          "--gps", "--known-height", "9", "--quiet"])
    assert code == 2 and "give one scale, not 2" in capsys.readouterr().err


# --- slow: structure from motion ---------------------------------------------------------

GPS_NOISE_M = 1.5
"""Each synthetic fix's error (per axis, independent): a good receiver in the open."""
# Measured (2026-11-29, pycolmap 4.2.1, two runs): against the true cameras, scale 0.9869 and
# heading 1.453 deg (what 1.5 m of GPS noise allows: about 1.5 / (22 m x sqrt(19)) = 1.6 %);
# against the same fit of the true cameras' centres (a perfect structure from motion),
# -3.8e-5 and under 0.0005 deg. The tolerances leave room for another machine's floating
# point.
SFM_SCALE_TOLERANCE = 2e-3
SFM_HEADING_TOLERANCE_DEG = 0.2
GPS_SCALE_TOLERANCE = 0.05
GPS_HEADING_TOLERANCE_DEG = 4.0


@pytest.mark.slow
def test_photos_of_a_textured_block_with_noisy_gps_come_out_in_metres_north_up(tmp_path,
                                                                             capsys):
    from test_photos_sfm import write_block_photos

    from dataset.importers.photos.pose_error import similarity_alignment

    truth = write_block_photos(tmp_path / "png")
    noise = np.random.default_rng(5).normal(0.0, GPS_NOISE_M, (len(truth), 2))
    gps_m = {}
    (tmp_path / "block").mkdir()
    for i, (name, (pose, _)) in enumerate(sorted(truth.items())):
        gps_m[name] = pose[:2, 3] + noise[i] + ([35.0, 20.0] if i == 7 else 0.0)  # one bad
        rgb = cv2.cvtColor(cv2.imread(str(tmp_path / "png" / name)), cv2.COLOR_BGR2RGB)
        Image.fromarray(rgb).save(tmp_path / "block" / name.replace(".png", ".jpg"),
                                  quality=95, exif=gps_exif(
                                      *wgs84_from_east_north(gps_m[name], ORIGIN)[0]))
    code = generate_main(["--photos", str(tmp_path / "block"), "--out", str(tmp_path / "out"),
                          "--gps", "--quiet"])
    assert code == 0, capsys.readouterr().err
    scene = read_method_input(tmp_path / "out" / "block")
    record = json.loads((tmp_path / "out" / "block" / "transforms.json").read_text())["photos"]
    assert list(record["gps"]["fixes_left_out"]) == ["v07.jpg"]
    assert record["gps"]["fixes_left_out"]["v07.jpg"] > OUTLIER_M
    assert record["gps"]["residual_median_m"] < 3 * GPS_NOISE_M
    names = [f.file_path.removeprefix("images/").replace(".jpg", ".png") for f in scene.frames]
    posed = np.stack([f.world_from_camera for f in scene.frames])
    true = np.stack([truth[n][0] for n in names])
    scale, rotation, _shift = similarity_alignment(posed[:, :3, 3], true[:, :3, 3])
    heading_deg = math.degrees(math.atan2(rotation[1, 0], rotation[0, 0]))
    assert np.degrees(np.arccos(rotation[2, 2])) < 0.2  # z up
    # Metres and north as far as the GPS noise allows...
    assert abs(scale - 1) < GPS_SCALE_TOLERANCE
    assert abs(heading_deg) < GPS_HEADING_TOLERANCE_DEG
    # ... and as a perfect structure from motion would give them: the same fit of the true
    # centres onto the same fixes (the bad one left out).
    kept = [n for n in names if n != "v07.png"]
    perfect = similarity_2d(np.stack([truth[n][0][:2, 3] for n in kept]),
                            np.stack([gps_m[n] for n in kept]))
    assert abs(scale * perfect.scale - 1) < SFM_SCALE_TOLERANCE
    assert abs(heading_deg + math.degrees(perfect.heading_rad)) < SFM_HEADING_TOLERANCE_DEG
    print(f"scale {scale:.5f}, heading {heading_deg:.3f} deg; against the perfect fit "
          f"{scale * perfect.scale - 1:.2e}, "
          f"{heading_deg + math.degrees(perfect.heading_rad):.3f} deg")
