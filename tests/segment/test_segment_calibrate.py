"""The window-area calibration: closed-form histograms, the offset in prediction, the CLI on
a trained network, bad records, and the committed weights' calibration."""

import json
import shutil

import numpy as np
import pytest
import torch

from envelope.classes import NUM_CLASSES, SemanticClass
from segment.calibrate import (
    MARGIN_EDGES,
    area_and_iou,
    main,
    unbiased_offset,
    validation_scenes,
    window_margin,
)
from segment.network import UNet, UNetConfig
from segment.segmenter import calibrated_offsets, network_segmenter, predict_labels
from segment.training_data import load_training_scenes
from segment.weights import RENDER_WEIGHTS, load_network, save_weights

WINDOW = SemanticClass.WINDOW
BIN = MARGIN_EDGES[1] - MARGIN_EDGES[0]


def _histograms(window_margins, other_margins):
    every = np.histogram(np.concatenate([window_margins, other_margins]), MARGIN_EDGES)[0]
    return every, np.histogram(window_margins, MARGIN_EDGES)[0]


def test_area_and_iou_and_the_unbiased_offset_in_closed_form():
    """100 window pixels at margin +1; 20 wall pixels at +0.5 (called window too) and 1000
    at -5. Offset 0: 120 windows predicted (ratio 1.2, IoU 100/120); the unbiased offset
    lies between -1 and -0.5 (100 predicted: ratio 1, IoU 1)."""
    every, window = _histograms(np.full(100, 1.0), np.r_[np.full(20, 0.5), np.full(1000, -5.0)])
    assert area_and_iou(every, window, 0.0) == pytest.approx((1.2, 100 / 120))
    offset = unbiased_offset(every, window)
    assert -1.0 - BIN <= offset <= -0.5 + BIN
    assert area_and_iou(every, window, offset) == pytest.approx((1.0, 1.0))
    # too few windows predicted: the offset is positive and brings all 100 back
    every, window = _histograms(np.r_[np.full(50, 0.5), np.full(50, -2.0)], np.full(900, -6.0))
    assert area_and_iou(every, window, 0.0) == pytest.approx((0.5, 0.5))
    offset = unbiased_offset(every, window)
    assert 2.0 - BIN <= offset <= 6.0
    assert area_and_iou(every, window, offset) == pytest.approx((1.0, 1.0))


def test_no_window_in_the_validation_frames_is_refused():
    every, window = _histograms(np.array([]), np.full(10, -3.0))
    with pytest.raises(ValueError, match="show no window"):
        area_and_iou(every, window, 0.0)


def _model():
    torch.manual_seed(0)
    return UNet(UNetConfig(base_channels=4, levels=3)).eval()


def test_the_offset_moves_pixels_into_and_out_of_the_window_class():
    model, rgb = _model(), np.random.default_rng(0).integers(0, 256, (32, 32, 3), np.uint8)
    plain = predict_labels(model, rgb)
    assert np.array_equal(predict_labels(model, rgb, logit_offsets=[0.0] * NUM_CLASSES), plain)
    up = [0.0] * NUM_CLASSES
    up[WINDOW] = 1e4
    assert (predict_labels(model, rgb, logit_offsets=up) == WINDOW).all()
    up[WINDOW] = -1e4
    assert not (predict_labels(model, rgb, logit_offsets=up) == WINDOW).any()
    # the margin is what the offset is compared with: window iff margin > -offset
    margin = window_margin(model, rgb, threads=1)
    for offset in (-0.3, 0.0, 0.4):
        up[WINDOW] = offset
        labels = predict_labels(model, rgb, logit_offsets=up)
        assert np.array_equal(labels == WINDOW, margin > -offset)


@pytest.mark.parametrize("offsets", [[0.0] * (NUM_CLASSES - 1), [0.0] * (NUM_CLASSES - 1)
                                     + [float("nan")], "1,2"])
def test_bad_offsets_in_a_record_are_refused(tmp_path, offsets):
    path = tmp_path / "w.pt"
    save_weights(path, _model(), {"calibration": {"logit_offsets": offsets}})
    with pytest.raises(ValueError, match="logit_offsets must be 6 finite numbers"):
        network_segmenter(path, threads=1)
    assert calibrated_offsets({}, path) is None


@pytest.mark.slow
def test_the_cli_calibrates_on_the_validation_buildings_it_names(clean_scene, tmp_path):
    """Weights whose record names the box scene as its validation building: the CLI writes
    the offset into a copy (the original untouched), and the segmenter of that copy uses it:
    its window area on those frames is the recorded one, no further from the exact area
    than before (an untrained network's margins come in lumps, so not exactly 1)."""
    model = _model()
    scene = load_training_scenes([clean_scene])[0]
    weights = tmp_path / "w.pt"
    save_weights(weights, model, {"validated_on": [scene.record]})
    before = weights.read_bytes()
    out = tmp_path / "calibrated.pt"
    assert main(["--data", str(clean_scene.parent), "--weights", str(weights), "--out",
                 str(out), "--frames", "100", "--threads", "1"]) == 0
    assert weights.read_bytes() == before
    _, record = load_network(out)
    cal = record["calibration"]
    assert cal["scenes"] == [f"{scene.record['folder']}/{scene.name}"]
    assert cal["logit_offsets"][WINDOW] == cal["window_offset"]
    assert sum(v != 0 for v in cal["logit_offsets"]) <= 1
    assert record == json.loads(out.with_suffix(".json").read_text())
    segment = network_segmenter(out, threads=1).segment
    predicted = exact = 0
    for frame in scene.frames:
        rgb, labels = scene.rgb_and_labels(frame)
        predicted += int((segment(rgb) == WINDOW).sum())
        exact += int((labels == WINDOW).sum())
    assert cal["area_ratio_after"] == pytest.approx(predicted / exact)
    assert abs(cal["area_ratio_after"] - 1.0) <= abs(cal["area_ratio_before"] - 1.0)
    assert cal["frames"] == len(scene.frames)


def test_weights_without_validation_buildings_or_with_none_found_are_refused(
        clean_scene, tmp_path):
    with pytest.raises(ValueError, match="record no validation buildings"):
        validation_scenes({"validated_on": []}, [clean_scene.parent])
    other = tmp_path / "elsewhere" / clean_scene.name
    shutil.copytree(clean_scene, other)
    with pytest.raises(ValueError, match=r"none of the validation buildings \['nope'\]"):
        validation_scenes({"validated_on": [{"scene": "nope"}]}, [other.parent])


def test_the_committed_weights_are_calibrated_on_their_validation_buildings():
    _, record = load_network(RENDER_WEIGHTS)
    cal = record["calibration"]
    names = sorted(f"{v['folder']}/{v['scene']}" for v in record["validated_on"])
    assert cal["scenes"] == names
    assert abs(cal["area_ratio_after"] - 1.0) < 0.01
    assert cal["iou_after"] >= cal["iou_before"] - 0.01
    offsets = calibrated_offsets(record, RENDER_WEIGHTS)
    assert offsets is not None and offsets[WINDOW] == cal["window_offset"]


def test_pixels_the_labels_do_not_count_are_left_out_of_the_histograms():
    from types import SimpleNamespace

    from segment.augment import IGNORE_LABEL
    from segment.calibrate import margin_histograms

    model = _model()
    rgb = np.random.default_rng(0).integers(0, 256, (12, 10, 3)).astype(np.uint8)
    labels = np.full((12, 10), SemanticClass.WALL, np.uint8)
    labels[2:6, 2:6] = WINDOW  # 16 window pixels
    labels[:, 8:] = IGNORE_LABEL  # 24 pixels not counted
    source = SimpleNamespace(frames=("a",), rgb_and_labels=lambda frame: (rgb, labels))
    every, window, read = margin_histograms(model, [source], frames=4, threads=1)
    assert read == 1 and every.sum() == 120 - 24 and window.sum() == 16
