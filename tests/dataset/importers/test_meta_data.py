"""dataset.importers.buildnet3d.meta_data: meta_data.json round trips, OpenGL <-> OpenCV poses,
class
remapping."""

import json
from dataclasses import replace

import numpy as np
import pytest
from paths import REPO_ROOT

from dataset.importers.buildnet3d.meta_data import (
    BUILDNET3D_LAYOUT,
    SDFSTUDIO_LAYOUT,
    class_mapping,
    opencv_from_opengl,
    read_meta_data,
    read_remapped_labels,
    remap_labels,
    write_meta_data,
)
from envelope.camera import Intrinsics, look_at, project_world_to_image
from envelope.classes import SemanticClass
from envelope.scene_record import Frame, Scene
from envelope.scenes.scene import read_scene, write_transforms

K = Intrinsics(40.0, 42.0, 16.5, 12.25, 32, 24)


def _scene(root) -> Scene:
    frames = (
        Frame("images/0.png", look_at([12, -3, 4], [0, 0, 2]), K, "train",
              depth_file_path="depth/0.png", semantic_file_path="semantics/0.png"),
        Frame("images/1.png", look_at([-2, 9, 1.5], [0, 0, 3]), K, "ideal", facade_id=2,
              semantic_file_path="semantics/1.png", normal_file_path="normals/1.png"),
        Frame("images/2.png", look_at([0.1, 0.2, 30], [0, 0, 0]), K, "eval"),
    )
    return Scene(root=root, frames=frames)


def _project_opencv(point, intrinsics, world_from_camera_cv):
    """Pinhole projection with an OpenCV camera (x right, y down, looking along +z)."""
    p = np.linalg.inv(world_from_camera_cv) @ np.append(point, 1.0)
    assert p[2] > 0, "point must be in front of an OpenCV camera (+z)"
    return intrinsics.K[:2] @ (p[:3] / p[2])


def test_known_pose_projects_target_to_centre_in_both_conventions():
    k = Intrinsics(50.0, 50.0, 20.0, 15.0, 40, 30)
    target = np.array([1.0, 2.0, 3.0])
    pose_gl = look_at([8.0, -4.0, 6.0], target)
    pose_cv = opencv_from_opengl(pose_gl)
    uv_gl, depth = project_world_to_image(target, k, pose_gl)
    np.testing.assert_allclose(uv_gl, [20.0, 15.0], atol=1e-9)
    np.testing.assert_allclose(_project_opencv(target, k, pose_cv), [20.0, 15.0], atol=1e-9)
    # Away from the centre both conventions agree too, and world up is image up (smaller v).
    above = target + [0.0, 0.0, 0.5]
    uv_up, _ = project_world_to_image(above, k, pose_gl)
    np.testing.assert_allclose(_project_opencv(above, k, pose_cv), uv_up, atol=1e-9)
    assert uv_up[1] < 15.0
    # The conversion is its own inverse and keeps the camera centre.
    np.testing.assert_allclose(opencv_from_opengl(pose_cv), pose_gl, atol=1e-15)
    np.testing.assert_array_equal(pose_cv[:3, 3], pose_gl[:3, 3])


@pytest.mark.parametrize("layout", [SDFSTUDIO_LAYOUT, BUILDNET3D_LAYOUT])
def test_write_read_round_trip(tmp_path, layout):
    scene = _scene(tmp_path)
    if layout is BUILDNET3D_LAYOUT:  # BuildNet3D keeps masks in semantic/
        scene = Scene(tmp_path, tuple(
            Frame(f.file_path, f.world_from_camera, f.intrinsics, f.split, f.facade_id,
                  None, f.semantic_file_path and f.semantic_file_path.replace(
                      "semantics/", "semantic/"))
            for f in scene.frames))
    write_meta_data(scene, tmp_path, layout=layout)
    back, mapping = read_meta_data(tmp_path / "meta_data.json", class_ids="envelope_bench",
                                   layout=layout, validate=False)  # JSON only: no images
    assert mapping.source == "envelope_bench"
    assert back.root == tmp_path
    for a, b in zip(scene.frames, back.frames, strict=True):
        np.testing.assert_allclose(b.world_from_camera, a.world_from_camera, atol=1e-12)
        assert b.intrinsics == a.intrinsics
        assert (b.file_path, b.split, b.facade_id) == (a.file_path, a.split, a.facade_id)
        assert (b.semantic_file_path, b.depth_file_path, b.normal_file_path) == (
            a.semantic_file_path, a.depth_file_path, a.normal_file_path)
    raw = json.loads((tmp_path / "meta_data.json").read_text())
    assert {"camera_model", "height", "width", "has_mono_prior", "worldtogt", "scene_box"} <= set(
        raw)
    assert set(raw["scene_box"]) == {"aabb", "near", "far", "radius", "collider_type"}
    frame = raw["frames"][0]
    assert np.asarray(frame["intrinsics"]).shape == (4, 4)
    expected = opencv_from_opengl(scene.frames[0].world_from_camera)
    if layout is BUILDNET3D_LAYOUT:
        expected = scene.frames[0].world_from_camera
        assert frame["rgb_path"] == "0.png" and frame["segmentation_path"] == "0.png"
    else:
        assert frame["rgb_path"] == "images/0.png"
    np.testing.assert_allclose(frame["camtoworld"], expected, atol=1e-12)


def test_transforms_json_round_trip_of_the_same_scene_agrees(tmp_path):
    scene = _scene(tmp_path)
    write_transforms(tmp_path, scene)
    write_meta_data(scene, tmp_path)
    via_transforms = read_scene(tmp_path, validate=False)  # JSON only: no image files
    via_meta, _ = read_meta_data(tmp_path, class_ids="envelope_bench", validate=False)
    for a, b in zip(via_transforms.frames, via_meta.frames, strict=True):
        np.testing.assert_allclose(a.world_from_camera, b.world_from_camera, atol=1e-12)
        assert a == replace(b, world_from_camera=a.world_from_camera)  # all other fields


def test_reads_buildnet3d_file_as_their_code_writes_it(tmp_path):
    # As EPFL-IMOS/buildnet3d writes it: OpenGL poses (key camera_to_world in their
    # renderer), 3x3 intrinsics, file names relative to images/ and semantic/.
    pose = look_at([10.0, 0.0, 3.0], [0.0, 0.0, 2.0])
    meta = {
        "camera_model": "OPEN_CV", "width": 64, "height": 48, "has_mono_prior": False,
        "scene_box": {"aabb": [[-1, -1, -1], [1, 1, 1]]},
        "frames": [{"rgb_path": "0000.png", "segmentation_path": "0000_mask.png",
                    "camera_to_world": pose.tolist(),
                    "intrinsics": [[60.0, 0, 32.0], [0, 60.0, 24.0], [0, 0, 1]]}],
    }
    (tmp_path / "meta_data.json").write_text(json.dumps(meta))
    scene, mapping = read_meta_data(tmp_path, layout=BUILDNET3D_LAYOUT, validate=False)
    (frame,) = scene.frames
    np.testing.assert_array_equal(frame.world_from_camera, pose)
    assert frame.intrinsics == Intrinsics(60.0, 60.0, 32.0, 24.0, 64, 48)
    assert (frame.file_path, frame.semantic_file_path) == ("images/0000.png",
                                                           "semantic/0000_mask.png")
    assert frame.split == "train" and mapping.source == "renderer"
    assert scene.extra["scene_box"] == meta["scene_box"]


def test_remap_renderer_and_generator_ids():
    renderer = class_mapping("renderer")
    ids = np.array([[0, 1, 2], [3, 4, 5]])
    expected = np.array([[0, 1, 4], [2, 3, 5]])  # door 2 -> 4, window 3 -> 2, roof 4 -> 3
    np.testing.assert_array_equal(remap_labels(ids, renderer), expected)
    assert remap_labels(ids, renderer).dtype == np.uint8
    generator = class_mapping("generator")
    np.testing.assert_array_equal(remap_labels(np.array([[0, 1], [2, 3]]), generator),
                                  [[0, SemanticClass.WALL], [SemanticClass.WINDOW,
                                                             SemanticClass.ROOF]])
    with pytest.raises(ValueError, match=r"ids \[4\].*'generator'"):
        remap_labels(np.array([[4]]), generator)


def test_remap_colour_coded_masks():
    renderer = class_mapping("renderer")
    colours = np.array(renderer.colours, dtype=np.uint8)[[[0, 3], [1, 2]]]  # (2, 2, 3)
    np.testing.assert_array_equal(remap_labels(colours, renderer), [[0, 2], [1, 4]])
    rgba = np.concatenate([colours, np.full((2, 2, 1), 255, np.uint8)], axis=-1)
    np.testing.assert_array_equal(remap_labels(rgba, renderer), [[0, 2], [1, 4]])
    with pytest.raises(ValueError, match="palette does not define"):
        remap_labels(np.full((1, 1, 3), 7, np.uint8), renderer)
    with pytest.raises(ValueError, match="no mask colours"):
        remap_labels(colours, class_mapping("envelope_bench"))


def test_scene_box_around_the_building_and_partial_boxes_completed(tmp_path):
    from dataset.importers.mesh.mesh_import import import_labelled_mesh

    example = REPO_ROOT / "dataset" / "examples" / "example_bim.ply"
    truth = import_labelled_mesh(example).truth
    write_meta_data(replace(_scene(tmp_path), building=truth), tmp_path)
    box = json.loads((tmp_path / "meta_data.json").read_text())["scene_box"]
    margin = 0.1 * np.linalg.norm([12.0, 8.0, 6.3])
    np.testing.assert_allclose(box["aabb"], [[-6 - margin, -4 - margin, -margin],
                                             [6 + margin, 4 + margin, 6.3 + margin]], atol=1e-9)
    partial = replace(_scene(tmp_path), extra={"scene_box": {"aabb": [[-1, -1, -1], [1, 1, 1]]}})
    write_meta_data(partial, tmp_path)
    box = json.loads((tmp_path / "meta_data.json").read_text())["scene_box"]
    assert box["aabb"] == [[-1, -1, -1], [1, 1, 1]]
    assert {"near", "far", "radius", "collider_type"} <= set(box)


def test_read_remapped_labels_from_id_and_colour_pngs(tmp_path):
    from PIL import Image

    renderer = class_mapping("renderer")
    ids = np.array([[0, 1], [2, 3]], dtype=np.uint8)
    Image.fromarray(ids).save(tmp_path / "ids.png")
    colours = np.array(renderer.colours, dtype=np.uint8)[ids]
    Image.fromarray(colours).save(tmp_path / "rgb.png")
    expected = [[0, 1], [4, 2]]
    np.testing.assert_array_equal(read_remapped_labels(tmp_path / "ids.png", renderer), expected)
    np.testing.assert_array_equal(read_remapped_labels(tmp_path / "rgb.png", renderer), expected)
    with pytest.raises(ValueError, match="does not exist"):
        read_remapped_labels(tmp_path / "none.png", renderer)


def test_bad_input_messages(tmp_path):
    with pytest.raises(ValueError, match="does not exist"):
        read_meta_data(tmp_path)
    (tmp_path / "meta_data.json").write_text('{"width": 4, "height": 4, "frames": [{}]}')
    with pytest.raises(ValueError, match="not a valid meta_data.json"):
        read_meta_data(tmp_path)
    with pytest.raises(ValueError, match="unknown class_ids"):
        read_meta_data(tmp_path, class_ids="cityscapes")
    scene = _scene(tmp_path)
    mixed = Scene(tmp_path, (scene.frames[0], Frame("x.png", np.eye(4), K.scaled(2), "train")))
    with pytest.raises(ValueError, match="one image size"):
        write_meta_data(mixed, tmp_path)
    with pytest.raises(ValueError, match="not inside semantic/"):
        write_meta_data(scene, tmp_path, layout=BUILDNET3D_LAYOUT)
