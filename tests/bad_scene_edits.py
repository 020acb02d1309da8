"""Ways to break a scene folder, each with the message it must produce (for test_bad_inputs).

Every edit takes the scene folder (a copy) and damages one thing in place:
the issue's table rows, corrupt/empty/mis-sized images, impossible depth,
malformed JSON, path traversal and symlinks, huge declared sizes.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from pathlib import Path

import numpy as np

from envelope.scenes.images import read_labels, write_depth_m, write_labels, write_rgb

Edit = Callable[[Path], None]
IDEAL = "ideal_0000.png"  # the first ideal view: the baselines read it
TRAIN = "train_0001.png"  # the first train view: neural3d reads it


def edit_transforms(root: Path, change: Callable[[dict], object]) -> None:
    """Load transforms.json, let ``change`` edit the dict in place, write it back."""
    meta = json.loads((root / "transforms.json").read_text())
    change(meta)
    (root / "transforms.json").write_text(json.dumps(meta))


def frame_of(meta: dict, stem: str) -> dict:
    """The frame whose image is ``images/<stem>``."""
    return next(f for f in meta["frames"] if f["file_path"] == f"images/{stem}")


def set_pose(stem: str, change: Callable[[np.ndarray], np.ndarray]) -> Edit:
    def edit(root: Path) -> None:
        def apply(meta: dict) -> None:
            frame = frame_of(meta, stem)
            pose = change(np.array(frame["transform_matrix"], dtype=float))
            frame["transform_matrix"] = [[float(x) for x in row] for row in pose]
        edit_transforms(root, apply)
    return edit


def set_frame(stem: str, key: str, value: object) -> Edit:
    return lambda root: edit_transforms(root, lambda m: frame_of(m, stem).update({key: value}))


def set_top(key: str, value: object) -> Edit:
    return lambda root: edit_transforms(root, lambda m: m.update({key: value}))


def write_file(relative: str, data: bytes) -> Edit:
    return lambda root: (root / relative).write_bytes(data)


def unknown_class_id(stem: str, new_id: int = 77) -> Edit:
    """Window pixels (class 2) of one semantic image set to ``new_id``."""
    def edit(root: Path) -> None:
        path = root / "semantics" / stem
        labels = read_labels(path)
        write_labels(path, np.where(labels == 2, new_id, labels))
    return edit


def truncate(relative: str) -> Edit:
    def edit(root: Path) -> None:
        data = (root / relative).read_bytes()
        (root / relative).write_bytes(data[: len(data) // 2])
    return edit


def symlink_out(relative: str, folder: bool = False) -> Edit:
    """Replace a file (or its whole folder) by a symlink to a copy outside the scene."""
    def edit(root: Path) -> None:
        outside = root.parent.parent / "outside"
        outside.mkdir(exist_ok=True)
        src = root / (str(Path(relative).parent) if folder else relative)
        target = outside / src.name
        os.replace(src, target)
        src.symlink_to(target, target_is_directory=folder)
    return edit


def zero_depth_on_building(stem: str) -> Edit:
    def edit(root: Path) -> None:
        write_depth_m(root / "depth" / stem, np.zeros((64, 64)), 0.001)
    return edit


SCENE_EDITS: dict[str, tuple[Edit, str]] = {
    # The table.
    "unknown_class_id_77": (unknown_class_id(IDEAL),
                            r"holds class ids the scene does not declare \(id 77 on \d+ pixels"),
    "frame_path_traversal": (set_frame(IDEAL, "file_path", "../../../../etc/passwd"),
                             r"leaves the scene folder \('\.\.'\)"),
    "nan_in_pose": (set_pose(IDEAL, lambda p: np.where(np.eye(4) > 0, np.nan, p)),
                    "the pose holds NaN or inf"),
    # Paths.
    "absolute_path": (set_frame(IDEAL, "semantic_file_path", "/etc/hostname"), "is absolute"),
    "windows_absolute_path": (set_frame(IDEAL, "depth_file_path", "C:\\scene\\d.png"),
                              "is absolute"),
    "symlink_file_out": (symlink_out(f"semantics/{IDEAL}"), "outside the scene folder"),
    "symlink_folder_out": (symlink_out(f"depth/{IDEAL}", folder=True),
                           "outside the scene folder"),
    "path_not_a_string": (set_frame(IDEAL, "semantic_file_path", 7), "not a relative file path"),
    # Poses and intrinsics.
    "inf_in_pose": (set_pose(IDEAL, lambda p: p + np.diag([0, 0, 0, np.inf])),
                    "NaN or inf"),
    "scaled_rotation": (set_pose(IDEAL, lambda p: p @ np.diag([2.0, 2.0, 2.0, 1.0])),
                        "rotation is not orthonormal"),
    "mirrored_pose": (set_pose(IDEAL, lambda p: p @ np.diag([-1.0, 1.0, 1.0, 1.0])),
                      "reflection"),
    "projective_last_row": (set_pose(IDEAL, lambda p: p + np.outer([0, 0, 0, 1], [0.5, 0, 0, 0])),
                            "last row"),
    "pose_3x3": (set_frame(IDEAL, "transform_matrix", np.eye(3).tolist()), "must be 4x4"),
    "nan_focal_length": (set_top("fl_x", float("nan")), "intrinsics hold NaN or inf"),
    "zero_focal_length": (set_top("fl_y", 0.0), "focal lengths must be positive"),
    "negative_width": (set_top("w", -64), "image size must be positive"),
    "huge_declared_size": (lambda r: edit_transforms(r, lambda m: m.update(w=200_000, h=200_000)),
                           "exceeds 100 megapixels"),
    "infinite_width": (set_top("w", float("inf")), "is malformed"),
    # Images.
    "empty_rgb": (write_file(f"images/{IDEAL}", b""), "not a readable image"),
    "garbage_semantics": (write_file(f"semantics/{IDEAL}", b"\x89PNG not really"),
                          "not a readable image"),
    "truncated_semantics": (truncate(f"semantics/{IDEAL}"), "cannot be read"),
    "missing_depth": (lambda r: (r / "depth" / IDEAL).unlink(), "does not exist"),
    "mis_sized_rgb": (lambda r: write_rgb(r / "images" / IDEAL, np.zeros((32, 48, 3), np.uint8)),
                      "is 48x32 but transforms.json says 64x64"),
    "mis_sized_semantics": (lambda r: write_labels(r / "semantics" / IDEAL, np.ones((64, 65))),
                            "is 65x64 but transforms.json says 64x64"),
    "rgb_semantics": (lambda r: write_rgb(r / "semantics" / IDEAL, np.ones((64, 64, 3), np.uint8)),
                      "semantic image must be single-channel"),
    "unknown_class_255": (unknown_class_id(IDEAL, 255), r"id 255 on \d+ pixels"),
    # Depth.
    "zero_depth_on_building": (zero_depth_on_building(IDEAL),
                               "building pixels have no valid depth"),
    "eight_bit_depth": (lambda r: write_labels(r / "depth" / IDEAL, np.ones((64, 64))),
                        "single-channel 16-bit"),
    "nan_depth_unit": (set_top("depth_unit_scale_factor", float("nan")),
                       "depth_unit_scale_factor must be a positive number"),
    "inf_depth_unit": (set_top("depth_unit_scale_factor", float("inf")),
                       "depth_unit_scale_factor must be a positive number"),
    "zero_depth_unit": (set_top("depth_unit_scale_factor", 0.0),
                        "depth_unit_scale_factor must be a positive number"),
    "negative_depth_unit": (set_top("depth_unit_scale_factor", -0.001),
                            "depth_unit_scale_factor must be a positive number"),
    # Malformed transforms.json.
    "transforms_truncated": (truncate("transforms.json"), "transforms.json is malformed"),
    "transforms_empty": (write_file("transforms.json", b""), "transforms.json is malformed"),
    "transforms_a_list": (write_file("transforms.json", b"[]"), "transforms.json is malformed"),
    "transforms_not_utf8": (write_file("transforms.json", b"\xff\xfe{"),
                            "transforms.json is malformed"),
    "frames_not_a_list": (set_top("frames", {"a": 1}), "transforms.json is malformed"),
    "frame_without_pose": (lambda r: edit_transforms(r, lambda m: frame_of(m, IDEAL).pop(
        "transform_matrix")), "transforms.json is malformed"),
    "unknown_split": (set_frame(IDEAL, "split", "test"), "unknown split 'test'"),
    "no_classes": (set_top("semantic_classes", []), "semantic_classes must list 1 to 256"),
    "classes_not_a_list": (set_top("semantic_classes", 5), "transforms.json is malformed"),
}
"""name -> (edit, regex the one-line error must match)."""

TABLE_ROWS = ("unknown_class_id_77", "frame_path_traversal", "nan_in_pose", "mis_sized_rgb")
"""The issue's table rows: run through both baselines."""
