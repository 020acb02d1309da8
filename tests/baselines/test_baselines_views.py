"""baselines.views: loading a protocol's views and skipping bad ones with one warning each."""

from dataclasses import replace

import numpy as np
import pytest
from baselines_synthetic import facade_pose, window_grid, write_facade_scene

from baselines.views import load_views
from envelope.camera import Intrinsics
from envelope.scenes.images import write_labels
from envelope.scenes.scene import read_method_input, read_scene, write_transforms
from envelope.scenes.scene_validation import InvalidSceneError

K = Intrinsics.from_fov(64, 48, 60.0)
FACADE = dict(length_m=12.0, height_m=9.0, windows=window_grid(12.0, 9.0, 4, 3, 1.6, 1.5))


@pytest.fixture
def scene(tmp_path):
    pose = facade_pose(12.0, 9.0, distance_m=16.0, azimuth_deg=0.0)
    views = [(1, pose), (2, pose), (2, pose), (3, pose), (4, pose), (5, pose), (6, pose)]
    s = write_facade_scene(tmp_path / "scene_a", views, K, **FACADE)
    f = list(s.frames)
    f[1] = replace(f[1], facade_id=None)  # no facade_id
    f[3] = replace(f[3], semantic_file_path=None)
    f[5] = replace(f[5], depth_file_path=None)
    write_transforms(s.root, replace(s, frames=tuple(f)))
    return read_method_input(s.root)


def test_bad_views_are_skipped_with_one_warning_each(scene):
    loaded = load_views(scene, "ideal", depth="required")
    assert [(v.facade_id, v.view_index) for v in loaded.views] == [(1, 0), (2, 0), (4, 0),
                                                                     (6, 0)]
    assert loaded.facade_ids == [1, 2, 3, 4, 5, 6]  # every named facade, usable or not
    w = loaded.warnings
    assert len(w) == 3
    assert w[0] == ("scene_a: view images/ideal_001.png skipped: the frame has no facade_id "
                    "in transforms.json")
    assert "view images/ideal_003.png (facade 3) skipped: the frame has no semantic_file_path" \
        in w[1]
    assert "(facade 5) skipped: the frame has no depth_file_path" in w[2]
    assert set(loaded.skipped) == {3, 5}


def test_missing_corrupt_or_mis_sized_images_make_the_scene_invalid(scene):
    (scene.root / "semantics" / "ideal_004.png").write_bytes(b"not a png")
    write_labels(scene.root / "semantics" / "ideal_006.png", np.zeros((10, 10)))
    (scene.root / "depth" / "ideal_002.png").unlink()
    with pytest.raises(InvalidSceneError) as info:
        read_scene(scene.root)
    message = str(info.value)
    assert "depth/ideal_002.png: does not exist" in message
    assert "ideal_004.png: is not a readable image" in message
    assert "semantics/ideal_006.png: is 10x10 but transforms.json says 64x48" in message


def test_optional_depth_keeps_the_view_and_warns(scene):
    loaded = load_views(scene, "ideal", depth="optional")
    by_facade = {v.facade_id: v for v in loaded.views}
    assert by_facade[5].depth_z_m is None
    assert by_facade[1].depth_z_m.shape == (48, 64)
    assert any("(facade 5): no area scale" in w for w in loaded.warnings)
    assert load_views(scene, "ideal", depth="no").views[0].depth_z_m is None


def test_unknown_protocol_and_missing_views_are_errors(scene):
    with pytest.raises(ValueError, match="unknown view protocol 'train'"):
        load_views(scene, "train", depth="no")
    with pytest.raises(ValueError, match="has no multi views"):
        load_views(scene, "multi", depth="no")
