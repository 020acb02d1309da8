"""envelope.scenes.labels: every method reads a frame's labels in our ids, whatever the scene
holds."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from envelope.camera import Intrinsics
from envelope.classes import SemanticClass
from envelope.scene_record import Frame, Scene
from envelope.scenes.images import write_labels
from envelope.scenes.labels import class_mapping, mapping_for_classes
from envelope.scenes.scene_validation import read_frame_labels


def _scene(tmp_path, labels, classes):
    write_labels(tmp_path / "m.png", labels)
    frame = Frame("i.png", np.eye(4), Intrinsics(2.0, 2.0, 1.0, 1.0, 2, 2), "train",
                  semantic_file_path="m.png")
    return Scene(root=tmp_path, frames=(frame,), semantic_classes=classes), frame


def test_a_renderer_scene_keeps_its_windows_windows(tmp_path):
    renderer = class_mapping("renderer")
    scene, frame = _scene(tmp_path, np.array([[3, 1], [4, 0]], np.uint8), renderer.names)
    assert read_frame_labels(scene, frame).tolist() == [
        [SemanticClass.WINDOW, SemanticClass.WALL], [SemanticClass.ROOF, 0]]


def test_ids_beyond_our_classes_are_an_error_not_a_misreading(tmp_path):
    scene, frame = _scene(tmp_path, np.array([[9, 1], [4, 0]], np.uint8),
                          class_mapping("envelope_bench").names)
    with pytest.raises(ValueError, match=r"does not declare \(id 9 on 1 pixels\)"):
        read_frame_labels(scene, frame)
    with pytest.raises(ValueError, match="neither the project's"):
        read_frame_labels(replace(scene, semantic_classes=("sky", "wall")), frame)
    assert mapping_for_classes(scene.semantic_classes) is None
