"""One scene folder: loads back exactly, records its generator, depth unit, atomic on Ctrl-C."""

import json
from dataclasses import replace

import numpy as np
import pytest
from conftest import assert_complete_scene, make_box_building

import dataset.scenes.scene_writer as scene_writer
from dataset.rendering.render import Raycaster, render_ground_truth
from dataset.scenes.scene_writer import (
    GenerateConfig,
    depth_unit_for,
    generate_scene,
    scene_is_finished,
)
from envelope.camera import look_at
from envelope.mesh import read_labelled_ply
from envelope.scenes.images import (
    read_depth_m,
    read_facade_ids,
    read_labels,
    read_normals,
    read_rgb,
)
from envelope.scenes.scene import read_scene

SMALL = GenerateConfig(resolution=40, views=6)


def test_generated_scene_loads_back_exactly(tmp_path):
    box = make_box_building()
    root = generate_scene(box, tmp_path, SMALL, seed=3, progress=False)
    assert root == tmp_path / "box"
    assert_complete_scene(root, SMALL)
    scene = read_scene(root)
    assert len(scene.frames_in("ideal")) == 4 and len(scene.frames_in("multi")) == 20
    assert scene.building == box.truth
    mesh = read_labelled_ply(root / "mesh.ply")
    np.testing.assert_array_equal(mesh.face_facade, box.mesh.face_facade)
    # Files hold exactly what the renderer gives for the recorded pose.
    rc = Raycaster(box.mesh)
    for frame in scene.frames_in("ideal")[:1] + scene.frames_in("train")[:1]:
        gt = render_ground_truth(rc, frame.intrinsics, frame.world_from_camera)
        depth = read_depth_m(scene.path(frame.depth_file_path), scene.depth_unit_scale_factor)
        np.testing.assert_allclose(depth, gt.depth_z_m, atol=scene.depth_unit_scale_factor / 2)
        np.testing.assert_array_equal(read_labels(scene.path(frame.semantic_file_path)), gt.labels)
        ids = read_facade_ids(scene.path(frame.instance_file_path))
        np.testing.assert_array_equal(ids, gt.facade_ids)
        normals = read_normals(scene.path(frame.normal_file_path))
        np.testing.assert_allclose(normals, gt.normals_world, atol=1e-4)
        assert read_rgb(scene.path(frame.file_path)).shape == (40, 40, 3)
    ideal = scene.frames_in("ideal")[0]
    assert read_facade_ids(scene.path(ideal.instance_file_path))[20, 20] == ideal.facade_id
    assert scene_is_finished(root, SMALL, seed=3)
    assert not scene_is_finished(root, SMALL, seed=4)
    assert not scene_is_finished(root, replace(SMALL, resolution=41), seed=3)


def test_depth_unit_grows_only_when_views_reach_past_16_bits():
    rc = Raycaster(make_box_building().mesh)
    near = look_at([0.0, -40.0, 5.0], [0.0, 0.0, 4.5])
    far = look_at([0.0, -100.0, 5.0], [0.0, 0.0, 4.5])  # farthest corner ~106 m
    assert depth_unit_for(0.001, rc, [near]) == 0.001
    assert depth_unit_for(0.001, rc, [near, far]) == pytest.approx(0.002)
    assert depth_unit_for(0.01, rc, [far]) == 0.01


def test_interrupted_scene_leaves_nothing_behind(tmp_path, monkeypatch):
    real = scene_writer._render_view
    count = {"n": 0}

    def interrupt_on_third(*args, **kwargs):
        count["n"] += 1
        if count["n"] == 3:
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    monkeypatch.setattr(scene_writer, "_render_view", interrupt_on_third)
    with pytest.raises(KeyboardInterrupt):
        generate_scene(make_box_building(), tmp_path, SMALL, seed=0, progress=False)
    assert list(tmp_path.iterdir()) == []


def test_transforms_records_the_generator(tmp_path):
    root = generate_scene(make_box_building(), tmp_path, SMALL, seed=9, progress=False)
    meta = json.loads((root / "transforms.json").read_text())
    assert meta["generator"]["seed"] == 9
    assert meta["generator"]["config"]["resolution"] == 40
    assert meta["depth_unit_scale_factor"] == 0.001
    assert meta["semantic_classes"][2] == "window"


def test_bad_config_and_names_are_refused(tmp_path):
    with pytest.raises(ValueError, match="resolution"):
        GenerateConfig(resolution=4)
    with pytest.raises(ValueError, match="train_fraction"):
        GenerateConfig(train_fraction=1.5)
    with pytest.raises(ValueError, match="plain folder name"):
        generate_scene(make_box_building(), tmp_path, SMALL, seed=0, name="../escape")


@pytest.mark.slow
def test_worker_processes_write_the_same_files(tmp_path):
    box = make_box_building()
    one = generate_scene(box, tmp_path / "one", SMALL, seed=5, progress=False)
    two = generate_scene(box, tmp_path / "two", SMALL, seed=5, progress=False, workers=2)
    files = sorted(p.relative_to(one) for p in one.rglob("*.png"))
    assert len(files) == 5 * (6 + 4 + 20)
    assert files == sorted(p.relative_to(two) for p in two.rglob("*.png"))
    for rel in files:
        assert (one / rel).read_bytes() == (two / rel).read_bytes(), rel
    frames_one = json.loads((one / "transforms.json").read_text())["frames"]
    assert frames_one == json.loads((two / "transforms.json").read_text())["frames"]
    with pytest.raises(ValueError, match="workers"):
        generate_scene(box, tmp_path, SMALL, seed=5, workers=0)
