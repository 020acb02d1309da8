"""Pose errors against the truth (dataset.importers.photos.pose_error) and stripping a
rendered scene down to photos (dataset.importers.photos.stripped_renders)."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from dataset.importers.photos.photo_folder import list_photos
from dataset.importers.photos.pose_error import pose_errors, similarity_alignment
from dataset.importers.photos.stripped_renders import known_pair, strip_renders
from envelope.camera import look_at
from envelope.scenes.scene import read_scene


def _true_poses(n: int = 8) -> np.ndarray:
    rng = np.random.default_rng(4)
    return np.stack([look_at(rng.uniform(-20, 20, 3) + [0, 0, 25], rng.uniform(-2, 2, 3))
                     for _ in range(n)])


def _moved(poses: np.ndarray, scale: float, rotation: np.ndarray, shift: np.ndarray):
    """The poses in another frame: x' = scale * R x + shift (cameras keep their shape)."""
    out = poses.copy()
    out[:, :3, :3] = rotation @ poses[:, :3, :3]
    out[:, :3, 3] = scale * poses[:, :3, 3] @ rotation.T + shift
    return out


def test_a_similar_copy_has_no_error_and_its_scale_comes_back():
    true = _true_poses()
    rotation = Rotation.from_euler("zyx", [40, 10, -5], degrees=True).as_matrix()
    shift = np.array([3.0, -1.0, 2.0])
    # recovered = true moved by the inverse similarity: aligning it back gives scale 1 / 0.5
    recovered = _moved(true, 0.5, rotation, shift)
    errors = pose_errors(recovered, true)
    assert errors.scale == pytest.approx(2.0, rel=1e-12)
    assert errors.scale_error == pytest.approx(1.0, rel=1e-12)
    assert errors.up_deg == pytest.approx(np.degrees(np.arccos(rotation[2, 2])), abs=1e-6)
    assert errors.rotation_deg.max() < 1e-5 and errors.position_m.max() < 1e-9
    scale, r, t = similarity_alignment(recovered[:, :3, 3], true[:, :3, 3])
    np.testing.assert_allclose(scale * recovered[:, :3, 3] @ r.T + t, true[:, :3, 3],
                               atol=1e-9)


def test_one_turned_camera_shows_its_turn_and_nothing_else():
    true = _true_poses()
    recovered = true.copy()
    recovered[3, :3, :3] = recovered[3, :3, :3] @ Rotation.from_rotvec(
        [0.0, np.radians(2.0), 0.0]).as_matrix()
    errors = pose_errors(recovered, true)
    assert errors.rotation_deg[3] == pytest.approx(2.0, abs=1e-9)
    assert np.delete(errors.rotation_deg, 3).max() < 1e-5
    assert errors.scale == pytest.approx(1.0, abs=1e-12)


def test_alignment_refuses_too_few_points():
    with pytest.raises(ValueError, match="N >= 3"):
        similarity_alignment(np.zeros((2, 3)), np.zeros((2, 3)))


def test_stripped_renders_are_photos_with_the_cameras_focal_length(clean_scene, tmp_path):
    truth = strip_renders(clean_scene, tmp_path / "photos", ("train", "eval"))
    scene = read_scene(clean_scene)
    orbit = [f for f in scene.frames if f.split in ("train", "eval")]
    assert sorted(truth) == sorted(f.file_path.split("/")[-1].replace(".png", ".jpg")
                                   for f in orbit)
    photos = list_photos(tmp_path / "photos")
    k = orbit[0].intrinsics
    # EXIF holds the 35 mm equivalent in whole millimetres: within half a millimetre of 36.
    for photo in photos:
        assert photo.focal_px == pytest.approx(k.fx, rel=0.5 / (k.fx / k.width * 36.0))
    assert not list((tmp_path / "photos").glob("*.png"))
    pair = known_pair(truth)
    first = truth[sorted(truth)[0]][:3, 3]
    assert pair.photo_a == sorted(truth)[0]
    assert pair.metres == pytest.approx(max(np.linalg.norm(p[:3, 3] - first)
                                            for p in truth.values()))
    with pytest.raises(ValueError, match="no frames of splits"):
        strip_renders(clean_scene, tmp_path / "none", ("street",))
