"""Training a few steps on a tiny scene, then the protocol's mask copies: cached by provenance,
blind to the truth, and nothing left behind by bad input."""

import json
import shutil
import time
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace
from typing import NamedTuple

import numpy as np
import pytest

import segment.train
from dataset.presets import preset_recipes
from envelope.classes import CLASS_NAMES
from envelope.scenes.images import read_labels, read_rgb, write_labels, write_rgb
from envelope.scenes.scene import find_scene_folders, read_scene
from segment.augment import AugmentConfig
from segment.evaluate import masks_scene_iou
from segment.network import UNetConfig
from segment.scene_masks import RECORD_KEY, predicted_scene
from segment.segmenter import Segmenter, network_segmenter
from segment.train import TrainConfig, main, train_segmenter
from segment.training_data import (
    EVALUATED_PRESETS,
    TRAINING_PRESET,
    load_training_scenes,
    split_by_building,
)

FEW_STEPS = TrainConfig(steps=3, batch=2, threads=1, val_every=0, validate_every=2,
                        network=UNetConfig(base_channels=4, levels=3),
                        augment=AugmentConfig(crop_px=32))


FAST_CPU_S = 0.012
"""The CPU time of the three steps on a fast machine (the clock is faked): the record used to
round it to 0.0 s."""


class Trained(NamedTuple):
    path: Path  # the weights
    wall_s: float  # the wall time the test measured around the training


@pytest.fixture(scope="module")
def trained(clean_scene, tmp_path_factory) -> Trained:
    """Weights trained for a few steps on the box scene (an imported building: no preset), on a
    process clock that says the training took ``FAST_CPU_S`` of CPU."""
    out = tmp_path_factory.mktemp("weights") / "box.pt"
    cpu_clock = iter([50.0])
    fast = SimpleNamespace(perf_counter=time.perf_counter,
                           process_time=lambda: next(cpu_clock, 50.0 + FAST_CPU_S))
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(segment.train, "time", fast)
        tic = time.perf_counter()
        train_segmenter([clean_scene], out, FEW_STEPS, progress=False)
        wall_s = time.perf_counter() - tic
    return Trained(out, wall_s)


@pytest.mark.slow
def test_a_few_steps_write_weights_with_their_record(trained, clean_scene):
    record = json.loads(trained.path.with_suffix(".json").read_text())
    assert record["steps_run"] == 3 and not record["cut_short"]
    assert [s["scene"] for s in record["trained_on"]] == [clean_scene.name]
    assert record["trained_on"][0]["preset"] is None and record["validated_on"] == []
    assert list(record["training_sets"]) == ["renders"]
    assert record["config"]["network"] == {"base_channels": 4, "levels": 3, "num_classes": 6,
                                           "stem_stride": 1, "working_long_side_px": None}
    assert len(record["class_weights"]) == len(CLASS_NAMES)
    assert record["provenance"]["config"]["seed"] == 0
    # The times keep milliseconds: a fast machine's 12 ms of CPU are 0.012 s, not 0.0. The wall
    # time lies within what the test measured around the call (to its rounding, 0.5 ms); reading
    # a scene and three steps take far more than 0.5 ms on any machine.
    assert record["cpu_time_s"] == FAST_CPU_S
    assert 0 < record["wall_time_s"] <= trained.wall_s + 5e-4


def test_training_refuses_evaluated_buildings(tiny_benchmark):
    with pytest.raises(ValueError, match="'tiny' preset, which is evaluated"):
        load_training_scenes([tiny_benchmark])


@pytest.mark.parametrize("preset", ["paper", "heldout", "lod3"])
def test_training_refuses_every_evaluated_preset(clean_scene, tmp_path, preset):
    scene = tmp_path / clean_scene.name
    shutil.copytree(clean_scene, scene)
    tf = json.loads((scene / "transforms.json").read_text())
    tf.setdefault("generator", {}).setdefault("provenance", {}).setdefault("inputs", {})[
        "preset"] = preset
    (scene / "transforms.json").write_text(json.dumps(tf))
    with pytest.raises(ValueError, match=f"'{preset}' preset, which is evaluated"):
        load_training_scenes([tmp_path])


def test_training_buildings_share_no_seed_with_an_evaluated_preset():
    assert {"paper", "tiny", "heldout", "lod3"} <= set(EVALUATED_PRESETS)
    assert TRAINING_PRESET not in EVALUATED_PRESETS
    train = {r.seed for r in preset_recipes(TRAINING_PRESET)}
    assert len(train) == 48
    for preset in EVALUATED_PRESETS:
        assert not train & {r.seed for r in preset_recipes(preset)}, preset


def test_the_split_keeps_a_building_on_one_side(clean_scene):
    (scene,) = load_training_scenes([clean_scene])
    twice = [scene, replace(scene, record={**scene.record, "resolution": 512})]
    train, val = split_by_building(twice, 1)  # every building validates
    assert train == [] and len(val) == 2
    with pytest.raises(ValueError, match="no building left to train on"):
        train_segmenter([clean_scene], Path("unused.pt"), replace(FEW_STEPS, val_every=1))


def test_mask_copies_are_cached_by_provenance(trained, clean_scene, tmp_path):
    segmenter = network_segmenter(trained.path, threads=1)
    copy = predicted_scene(clean_scene, tmp_path, segmenter, progress=False)
    scene = read_scene(copy)
    record = json.loads((copy / "transforms.json").read_text())[RECORD_KEY]
    assert record["config"]["segmenter"] == str(trained.path)
    assert set(record["config"]) >= {"weights", "code", "torch"}
    assert set(record["code"]) == {"segment.scene_masks"}
    first = scene.frames[0]
    mask = copy / first.semantic_file_path
    assert read_labels(mask).shape == read_rgb(copy / first.file_path).shape[:2]
    stamp = mask.stat().st_mtime_ns
    assert predicted_scene(clean_scene, tmp_path, segmenter, progress=False) == copy
    assert mask.stat().st_mtime_ns == stamp  # reused, not rewritten
    # the truth and the other inputs are the original's files; the masks are new files
    for name in ("building.json", "mesh.ply", first.file_path, first.depth_file_path):
        assert (copy / name).samefile(clean_scene / name)
    assert not mask.samefile(clean_scene / first.semantic_file_path)
    # another segmenter's masks replace the copy
    other = Segmenter("zeros", lambda rgb: np.zeros(rgb.shape[:2], np.uint8), {"v": 1})
    predicted_scene(clean_scene, tmp_path, other, progress=False)
    assert (read_labels(mask) == 0).all()


def test_the_segmenter_never_sees_the_truth(trained, clean_scene, tmp_path):
    """Scrambled exact masks, instances and a changed building.json give the same masks."""
    segmenter = network_segmenter(trained.path, threads=1)
    changed = shutil.copytree(clean_scene, tmp_path / "source" / clean_scene.name)
    rng = np.random.default_rng(0)
    for fr in read_scene(changed).frames:
        for rel in (fr.semantic_file_path, fr.instance_file_path):
            labels = read_labels(changed / rel)
            write_labels(changed / rel, rng.permutation(labels.ravel()).reshape(labels.shape))
    truth = json.loads((changed / "building.json").read_text())
    (changed / "building.json").write_text(json.dumps({**truth, "wwr": 0.99}))
    (changed / "mesh.ply").unlink()
    a = predicted_scene(clean_scene, tmp_path / "a", segmenter, progress=False)
    b = predicted_scene(changed, tmp_path / "b", segmenter, progress=False)
    for fa, fb in zip(read_scene(a).frames, read_scene(b).frames, strict=True):
        assert (read_labels(a / fa.semantic_file_path)
                == read_labels(b / fb.semantic_file_path)).all()


def test_a_copy_of_some_splits_holds_their_frames_and_no_other_exact_mask(clean_scene, tmp_path):
    source = read_scene(clean_scene)
    walls = Segmenter("walls", lambda rgb: np.ones(rgb.shape[:2], np.uint8), {})
    copy = predicted_scene(clean_scene, tmp_path, walls, splits=("ideal",), progress=False)
    scene = read_scene(copy)
    ideal = [f.file_path for f in source.frames if f.split == "ideal"]
    assert ideal and [f.file_path for f in scene.frames] == ideal
    assert all((read_labels(copy / f.semantic_file_path) == 1).all() for f in scene.frames)
    for fr in source.frames:  # the exact masks of the frames left out are not in the copy
        if fr.split != "ideal":
            assert not (copy / fr.semantic_file_path).exists()
            assert (copy / fr.file_path).samefile(clean_scene / fr.file_path)
    record = json.loads((copy / "transforms.json").read_text())[RECORD_KEY]
    assert record["config"]["splits"] == ["ideal"]
    # the IoU is over the copy's frames; every frame: the copy is made again
    assert masks_scene_iou(source, scene).frames == len(ideal)
    predicted_scene(clean_scene, tmp_path, walls, progress=False)
    assert len(read_scene(copy).frames) == len(source.frames)


def test_a_copy_a_killed_run_left_unfinished_is_no_scene(clean_scene, tmp_path):
    """A run killed by a signal leaves ``.<scene>.<random>.partial`` (hard links of the
    source, some masks replaced): it must not be measured as one more building."""
    data = tmp_path / "masks"
    zeros = Segmenter("zeros", lambda rgb: np.zeros(rgb.shape[:2], np.uint8), {})
    done = predicted_scene(clean_scene, data, zeros, progress=False)
    shutil.copytree(done, data / f".{clean_scene.name}.x1y2.partial")
    assert find_scene_folders(data) == find_scene_folders(data, with_images=True) == [done]


@pytest.mark.parametrize("answer", ["shape", "dtype", "ids"])
def test_a_refused_answer_leaves_nothing_cached(clean_scene, tmp_path, answer):
    def bad(rgb):
        labels = np.zeros(rgb.shape[:2], np.uint8)
        return {"shape": labels[1:], "dtype": labels.astype(np.int32), "ids": labels + 9}[answer]

    with pytest.raises(ValueError, match="segmenter 'bad' returned"):
        predicted_scene(clean_scene, tmp_path, Segmenter("bad", bad, {}), progress=False)
    assert list(tmp_path.iterdir()) == []


def test_rgb_of_another_size_than_its_frame_is_refused_and_nothing_cached(clean_scene, tmp_path):
    source = shutil.copytree(clean_scene, tmp_path / "source" / clean_scene.name)
    first = read_scene(source).frames[0]
    write_rgb(source / first.file_path, np.zeros((10, 12, 3), np.uint8))
    zeros = Segmenter("zeros", lambda rgb: np.zeros(rgb.shape[:2], np.uint8), {})
    with pytest.raises(ValueError, match=r"12x10|size"):
        predicted_scene(source, tmp_path / "masks", zeros, progress=False)
    assert not (tmp_path / "masks").exists() or list((tmp_path / "masks").iterdir()) == []


def test_the_cli_explains_itself_and_refuses_bad_options(clean_scene, tmp_path, capsys):
    with pytest.raises(SystemExit) as done:
        main(["--help"])
    assert done.value.code == 0 and "never evaluated" in capsys.readouterr().out
    assert main(["--data", str(clean_scene), "--out", str(tmp_path / "w.bin")]) == 2
    assert "must name a .pt file" in capsys.readouterr().err
    assert main(["--data", str(tmp_path / "none"), "--out", str(tmp_path / "w.pt")]) == 2
    assert "does not exist" in capsys.readouterr().err
    assert not (tmp_path / "w.pt").exists()


@pytest.mark.slow
def test_a_strided_network_at_a_working_scale_trains_and_segments_photos_of_any_size(
        clean_scene, tmp_path):
    out = tmp_path / "wide.pt"
    assert main(["--data", str(clean_scene), "--out", str(out), "--steps", "2", "--batch", "2",
                 "--crop", "32", "--threads", "1", "--val-every", "0", "--base-channels", "4",
                 "--levels", "3", "--stem-stride", "2", "--working-px", "48",
                 "--render-frames", "2", "--scale", "0.8", "1.2", "--quiet"]) == 0
    record = json.loads(out.with_suffix(".json").read_text())
    assert record["config"]["network"]["working_long_side_px"] == 48
    assert record["config"]["augment"]["scale"] == [0.8, 1.2]
    assert [s["frames_read"] for s in record["trained_on"]] == [2]
    segment = network_segmenter(out, threads=1).segment
    for shape in ((31, 77, 3), (200, 90, 3)):
        labels = segment(np.random.default_rng(0).integers(0, 256, shape).astype(np.uint8))
        assert labels.shape == shape[:2] and labels.max() < len(CLASS_NAMES)
