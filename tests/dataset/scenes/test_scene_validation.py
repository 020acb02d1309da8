"""envelope.scenes.scene_validation: pose tolerance, paths inside the folder, warning kinds."""

import numpy as np
import pytest

from envelope.camera import look_at
from envelope.scenes.scene_validation import ROTATION_TOLERANCE, pose_problem, resolve_inside
from envelope.warnings_summary import warning_kind


def test_a_float32_round_trip_pose_is_proper_and_a_scaled_one_is_not():
    pose = look_at([10.0, -4.0, 3.0], [0.0, 0.0, 2.0])
    assert pose_problem(pose.astype(np.float32)) is None
    scaled = pose @ np.diag([1 + 2 * ROTATION_TOLERANCE, 1.0, 1.0, 1.0])
    assert "not orthonormal" in pose_problem(scaled)


@pytest.mark.parametrize("relative, ok", [
    ("images/a.png", True), ("images/../images/a.png", False), ("/etc/passwd", False),
    ("C:/x.png", False), ("", False),
])
def test_paths_must_stay_inside_the_scene(tmp_path, relative, ok):
    if ok:
        assert resolve_inside(tmp_path, relative) == (tmp_path / relative).resolve()
    else:
        with pytest.raises(ValueError):
            resolve_inside(tmp_path, relative)


def test_symlink_inside_the_folder_is_fine(tmp_path):
    (tmp_path / "real.png").write_bytes(b"")
    (tmp_path / "link.png").symlink_to(tmp_path / "real.png")
    assert resolve_inside(tmp_path, "link.png") == (tmp_path / "real.png").resolve()


def test_warning_kind_ignores_ids_paths_and_counts():
    assert warning_kind("s_0: view images/a_3.png (facade 3) skipped: cut off") == \
        warning_kind("s_1: view images/a_9.png (facade 12) skipped: cut off")
    assert warning_kind("a cut off") != warning_kind("no depth")
