"""IoU of masks: closed-form confusion counts and IoUs, pooled per building, and the CLI."""

import numpy as np
import pytest

from envelope.classes import NUM_CLASSES, SemanticClass
from envelope.scenes.images import read_rgb
from envelope.scenes.scene import read_scene
from envelope.scenes.scene_validation import read_frame_labels
from segment.evaluate import (
    confusion_matrix,
    evenly_spaced,
    iou_per_class,
    main,
    mean_iou,
    segmenter_scene_iou,
)
from segment.segmenter import Segmenter

W, G = SemanticClass.WALL, SemanticClass.WINDOW


def test_iou_of_two_overlapping_rectangles():
    exact = np.full((10, 10), W, np.uint8)
    exact[2:6, 2:6] = G  # 16 px
    predicted = np.full((10, 10), W, np.uint8)
    predicted[3:7, 2:6] = G  # 16 px, 12 shared
    confusion = confusion_matrix(predicted, exact)
    assert confusion.sum() == 100 and confusion[G, G] == 12 and confusion[G, W] == 4
    iou = iou_per_class(confusion)
    assert iou[G] == pytest.approx(12 / 20)
    assert iou[W] == pytest.approx(80 / 88)
    assert np.isnan(iou[SemanticClass.ROOF])  # in neither mask


def test_ids_beyond_the_classes_are_not_counted_and_shapes_must_match():
    exact = np.array([[0, 1], [2, 255]], np.uint8)
    assert confusion_matrix(exact, exact).sum() == 3
    with pytest.raises(ValueError, match="different shapes"):
        confusion_matrix(np.zeros((2, 2)), np.zeros((2, 3)))


def test_means_skip_absent_classes_without_warnings():
    ious = np.full((2, NUM_CLASSES), np.nan)
    ious[0, G], ious[1, G], ious[1, W] = 0.5, 0.7, 1.0
    with np.errstate(all="raise"):
        mean = mean_iou(ious)
    assert mean[G] == pytest.approx(0.6) and mean[W] == 1.0 and np.isnan(mean[0])


def test_evenly_spaced_keeps_first_and_last():
    assert evenly_spaced(list(range(10)), 3) == (0, 4, 9)  # 4.5 rounds to even
    assert evenly_spaced([1, 2], 5) == (1, 2) and evenly_spaced([1, 2], None) == (1, 2)


def test_a_perfect_segmenter_scores_one(clean_scene):
    """A segmenter that returns the exact mask of the image it is shown gets IoU 1."""
    scene = read_scene(clean_scene)
    exact = {read_rgb(scene.path(fr.file_path)).tobytes(): read_frame_labels(scene, fr)
             for fr in scene.frames}
    oracle = Segmenter("oracle", lambda rgb: exact[rgb.tobytes()], {})
    result = segmenter_scene_iou(scene, oracle, max_frames=4)
    assert result.frames == 4 and result.family == "imported"
    assert result.window_iou == 1.0 and np.nanmin(result.iou) == 1.0


def test_the_cli_prints_per_building_and_family_rows(clean_scene, capsys, tmp_path):
    assert main(["--data", str(clean_scene), "--max-frames", "2", "--threads", "1",
                 "--csv", str(tmp_path / "iou.csv")]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("scene,family,frames,background_iou,wall_iou,window_iou")
    assert out[1].startswith(f"{clean_scene.name},imported,2,")
    assert out[2].startswith("mean,imported,1,")
    assert (tmp_path / "iou.csv").read_text().splitlines()[1:] == out
    assert main(["--data", str(tmp_path / "none")]) == 2
    assert "does not exist" in capsys.readouterr().err
    assert main(["--data", str(clean_scene), "--max-frames", "0"]) == 2
