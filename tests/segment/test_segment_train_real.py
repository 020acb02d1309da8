"""Training on renders plus labelled real photos: the real sets' train photos are trained
on, their val photos pick the weights, their test photos are never read; and the
augmentations added for real photos (perspective, occluders, shadows)."""

import csv
import io
import json
from dataclasses import replace

import numpy as np
import pytest
from real_set_folders import LMF_PHOTOS, write_cmp, write_labelmefacade

from envelope.classes import SemanticClass
from segment.augment import IGNORE_LABEL, REAL_PHOTO_AUGMENT, AugmentConfig, augment_frame
from segment.calibrate import main as calibrate_main
from segment.calibrate import validation_scenes
from segment.network import UNetConfig
from segment.real_sets.splits import LIST_DIR
from segment.real_training import real_sources
from segment.train import TrainConfig, main, train_segmenter
from segment.weights import load_network

FEW_REAL_STEPS = TrainConfig(steps=3, batch=4, threads=1, val_every=0, validate_every=2,
                             real_share=0.5, network=UNetConfig(base_channels=4, levels=3),
                             augment=replace(REAL_PHOTO_AUGMENT, crop_px=32))
# No random change at all but the one under test.
PLAIN = AugmentConfig(crop_px=32, scale=(1.0, 1.0), flip_p=0.0, brightness=(1, 1),
                      contrast=(1, 1), saturation=(1, 1), channel_gain=(1, 1), gamma=(1, 1),
                      blur_p=0.0, noise_p=0.0, jpeg_p=0.0)


def _test_names() -> set[str]:
    names = set()
    for set_name in ("labelmefacade", "cmp"):
        rows = csv.DictReader(io.StringIO((LIST_DIR / f"{set_name}.csv").read_text()))
        names |= {r["name"] for r in rows if r["split"] != "train" and r["split"] != "val"}
    return names


def test_real_sources_hold_train_and_val_photos_only(tmp_path):
    roots = {"labelmefacade": write_labelmefacade(tmp_path / "lmf"),
             "cmp": write_cmp(tmp_path / "cmp")}
    train, val = real_sources(roots)
    assert [s.name for s in train] == ["labelmefacade/train", "cmp/train"]
    assert [s.name for s in val] == ["labelmefacade/val", "cmp/val"]
    used = {p.name for s in train + val for p in s.frames}
    assert not used & _test_names()
    assert {p.name for p in train[0].frames} == {n for n, _, s in LMF_PHOTOS if s == "train"}
    rgb, labels = train[1].rgb_and_labels(train[1].frames[0])
    assert rgb.shape[:2] == labels.shape
    with pytest.raises(ValueError, match="val_photos must be >= 1"):
        real_sources(roots, val_photos=0)


@pytest.mark.slow
def test_a_few_steps_on_renders_and_real_photos(clean_scene, tmp_path):
    roots = {"labelmefacade": write_labelmefacade(tmp_path / "lmf"),
             "cmp": write_cmp(tmp_path / "cmp")}
    out = tmp_path / "real.pt"
    train_segmenter([clean_scene], out, FEW_REAL_STEPS, real=roots, progress=False)
    record = json.loads(out.with_suffix(".json").read_text())
    assert [s.get("scene", s.get("set")) for s in record["trained_on"]] == [
        clean_scene.name, "labelmefacade", "cmp"]
    assert [(s["set"], s["split"]) for s in record["validated_on"]] == [
        ("labelmefacade", "val"), ("cmp", "val")]
    named = {n for s in record["trained_on"] + record["validated_on"] for n in s.get("names", [])}
    assert named and not named & _test_names()
    assert record["steps_run"] == 3 and "val_window_iou" in record["history"][-1]
    assert set(record["provenance"]["inputs"]["real_split_lists"]) == {"labelmefacade", "cmp"}
    sets = record["training_sets"]  # every set it read, with its licence
    assert list(sets) == ["renders", "cmp", "labelmefacade"]
    assert sets["labelmefacade"]["licence"].startswith("non-commercial research use only")
    assert all(s["licence"] and s["repository"] for s in sets.values())
    load_network(out)
    with pytest.raises(ValueError, match="picked on real validation photos.*--labelmefacade"):
        validation_scenes(record, [clean_scene])  # not calibrated on renders
    # Calibrated on the very validation photos that picked the weights, read from the sets.
    sources = validation_scenes(record, [], roots)
    assert [[p.name for p in s.frames] for s in sources] == [
        v["names"] for v in record["validated_on"]]
    assert calibrate_main(["--weights", str(out), "--out", str(tmp_path / "cal.pt"),
                           "--labelmefacade", str(roots["labelmefacade"]),
                           "--cmp", str(roots["cmp"]), "--threads", "1"]) == 0
    calibration = json.loads((tmp_path / "cal.json").read_text())["calibration"]
    assert calibration["frames"] == 2 and len(calibration["logit_offsets"]) == 6
    # A copy holding other validation photos than the record names is refused.
    other = {"labelmefacade": roots["labelmefacade"], "cmp": write_cmp(tmp_path / "cmp2")}
    (other["cmp"] / "base" / "cmp_b0002.jpg").unlink()
    with pytest.raises(ValueError, match="does not hold the validation photos"):
        validation_scenes(record, [], other)


@pytest.mark.slow
def test_the_cli_trains_with_real_sets(clean_scene, tmp_path, capsys):
    lmf = write_labelmefacade(tmp_path / "lmf")
    out = tmp_path / "cli.pt"
    assert main(["--data", str(clean_scene), "--labelmefacade", str(lmf), "--out", str(out),
                 "--steps", "2", "--batch", "2", "--crop", "32", "--threads", "1",
                 "--val-every", "0", "--validate-every", "2", "--quiet"]) == 0
    record = json.loads(out.with_suffix(".json").read_text())
    assert record["config"]["augment"]["perspective_p"] == REAL_PHOTO_AUGMENT.perspective_p
    assert record["config"]["real_share"] == 0.5
    assert main(["--data", str(clean_scene), "--out", str(out), "--real-share", "2"]) == 2
    assert "real_share must be in [0, 1]" in capsys.readouterr().err


def _frame():
    rng = np.random.default_rng(3)
    rgb = rng.integers(40, 220, (32, 32, 3), dtype=np.uint8)
    labels = np.full((32, 32), SemanticClass.WALL, np.uint8)
    labels[8:16, 8:16] = SemanticClass.WINDOW
    return rgb, labels


def test_perspective_moves_labels_with_the_image_and_ignores_what_comes_from_outside():
    rgb, labels = _frame()
    config = replace(PLAIN, perspective_p=1.0, perspective_share=0.2)
    outside_seen = False
    for seed in range(10):
        x, y = augment_frame(rgb, labels, config, np.random.default_rng(seed))
        assert set(np.unique(y)) <= {SemanticClass.WALL, SemanticClass.WINDOW, IGNORE_LABEL}
        outside = y == IGNORE_LABEL
        black = (x == 0).all(axis=2)  # the frame's colours are 40..220: black is outside
        assert outside[black].all() and black.sum() < outside.sum() + 1
        outside_seen |= bool(black.any())
    assert outside_seen


def test_an_occluder_is_a_background_bar_of_one_colour():
    rgb, labels = _frame()
    config = replace(PLAIN, occluder_p=1.0, occluder_width_share=(0.25, 0.25))
    x, y = augment_frame(rgb, labels, config, np.random.default_rng(0))
    bar = np.flatnonzero((y == SemanticClass.BACKGROUND).all(axis=0))
    assert len(bar) == 8 and np.all(np.diff(bar) == 1)  # 0.25 of 32 px, one strip
    assert (y == SemanticClass.BACKGROUND).sum() == 8 * 32
    strip = x[:, bar].reshape(-1, 3)
    assert np.allclose(strip, strip[0])


def test_a_shadow_only_darkens():
    rgb, labels = _frame()
    config = replace(PLAIN, shadow_p=1.0, shadow_gain=(0.5, 0.5))
    darkest = []
    for seed in range(10):
        plain, y_plain = augment_frame(rgb, labels, PLAIN, np.random.default_rng(seed))
        shaded, y = augment_frame(rgb, labels, config, np.random.default_rng(seed))
        np.testing.assert_array_equal(y, y_plain)  # the same crop, labels untouched
        assert (shaded <= plain + 1e-6).all()
        lit = plain > 0.1
        darkest.append(float((shaded[lit] / plain[lit]).min()))
    assert min(darkest) == pytest.approx(0.5, abs=1e-4)  # the gain, where the shadow falls
