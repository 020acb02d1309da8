"""dataset.buildnet3d_export: our scene written for the official BuildNet3D dataparser and
read back by a small reader written here from that dataparser's rules, not ours."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import cv2
import numpy as np
import pytest
from neural3d_scene import write_ring_scene
from PIL import Image

from dataset.buildnet3d_export import main as export_main
from envelope.classes import CLASS_NAMES
from envelope.scenes.images import read_rgb
from envelope.scenes.scene import read_scene
from envelope.scenes.scene_validation import read_frame_depth_m, read_frame_labels


def read_like_buildnet_dataparser(root: Path) -> dict:
    """What EPFL-IMOS/buildnet3d's BuildNet dataparser (buildnet3d/data/buildnet_dataparser.py)
    and nerfstudio's semantic reader make of ``root``, rule by rule:

    - meta_data.json in the data folder (:57-62); rgb at ``images/<rgb_path>`` (:82),
      segmentation at ``semantic/<segmentation_path>`` (:85), ``depth_path`` and
      ``normals_path`` relative to the data folder (:88-89);
    - fx, fy, cx, cy = intrinsics[0,0], [1,1], [0,2], [1,2] (:91-97); ``camtoworld`` as
      nerfstudio's camera_to_worlds[:, :3, :4] (:92, :205), an OpenGL camera;
    - split: "train" in the file name, else "eval", else an error (:112-122);
    - ``scene_box.aabb`` (:183-185), ``height`` and ``width`` (:196);
    - classes = keys of segmentation_data.json, colours = its values (:212-214);
    - labels: ``np.array(Image.open(path), dtype="int64")`` (nerfstudio
      data/utils/data_utils.py get_semantics_and_mask_tensors_from_path), so one id per pixel;
    - depth: ``cv2.imread(…, IMREAD_ANYDEPTH) * 1e-3`` (data_utils.get_depth_image_from_path,
      depth_unit_scale_factor 1e-3 at :29).
    """
    meta = json.loads((root / "meta_data.json").read_text())
    seg = json.loads((root / "segmentation_data.json").read_text())
    frames = []
    for fr in meta["frames"]:
        name = Path(fr["rgb_path"]).name
        if "train" in name:
            split = "train"
        elif "eval" in name:
            split = "eval"
        else:
            raise ValueError(f"Unrecognized rgb filename '{name}'")
        k = np.asarray(fr["intrinsics"], dtype=np.float32)
        semantics = np.array(Image.open(root / "semantic" / fr["segmentation_path"]),
                             dtype="int64")
        depth = cv2.imread(str(root / fr["depth_path"]), cv2.IMREAD_ANYDEPTH) * 1e-3
        frames.append({"split": split, "image": root / "images" / fr["rgb_path"],
                       "fx": k[0, 0], "fy": k[1, 1], "cx": k[0, 2], "cy": k[1, 2],
                       "c2w": np.asarray(fr["camtoworld"], dtype=np.float32)[:3, :4],
                       "semantics": semantics, "depth": depth})
    return {"frames": frames, "classes": list(seg.keys()), "colors": list(seg.values()),
            "aabb": np.asarray(meta["scene_box"]["aabb"]), "hw": (meta["height"], meta["width"])}


@pytest.fixture(scope="module")
def exported(tmp_path_factory, box_building):
    root = tmp_path_factory.mktemp("export")
    scene = read_scene(write_ring_scene(box_building, root / "scene", size_px=32, n_train=6,
                                        n_eval=2))
    with contextlib.redirect_stdout(io.StringIO()):
        assert export_main([str(scene.root), str(root / "out")]) == 0
    return scene, root / "out"


def test_the_dataparser_reads_poses_intrinsics_labels_depth_and_split(exported):
    scene, out = exported
    parsed = read_like_buildnet_dataparser(out)
    assert parsed["classes"] == list(CLASS_NAMES)
    assert len({tuple(c) for c in parsed["colors"]}) == len(CLASS_NAMES)
    assert parsed["aabb"].shape == (2, 3)
    ours = [f for f in scene.frames if f.split in ("train", "eval")]
    assert [p["split"] for p in parsed["frames"]] == [f.split for f in ours]
    for p, fr in zip(parsed["frames"], ours):
        k = fr.intrinsics
        assert parsed["hw"] == (k.height, k.width)
        np.testing.assert_allclose([p["fx"], p["fy"], p["cx"], p["cy"]],
                                   [k.fx, k.fy, k.cx, k.cy], rtol=1e-6)
        np.testing.assert_allclose(p["c2w"], fr.world_from_camera[:3, :4], atol=1e-5)
        assert p["semantics"].ndim == 2
        np.testing.assert_array_equal(p["semantics"], read_frame_labels(scene, fr))
        np.testing.assert_array_equal(read_rgb(p["image"]), read_rgb(scene.path(fr.file_path)))
        np.testing.assert_allclose(p["depth"], read_frame_depth_m(scene, fr), atol=5e-4)


def test_the_export_imports_back(exported, tmp_path):
    """The export is a dataparser-layout folder: --buildnet3d reads it back (our class
    names in segmentation_data.json, ids in semantic/, camtoworld as nerfstudio's)."""
    from dataset.generate import main as generate_main

    scene, out = exported
    with contextlib.redirect_stdout(io.StringIO()):
        assert generate_main(["--buildnet3d", str(out), "--out", str(tmp_path)]) == 0
    back = read_scene(tmp_path / "out")
    views = [f for f in back.frames if f.split in ("train", "eval")]
    ours = [f for f in scene.frames if f.split in ("train", "eval")]
    assert [f.split for f in views] == [f.split for f in ours]
    for a, b in zip(views, ours):
        np.testing.assert_allclose(a.world_from_camera, b.world_from_camera, atol=1e-9)
        np.testing.assert_array_equal(read_frame_labels(back, a), read_frame_labels(scene, b))


def test_a_scene_without_train_frames_is_a_clear_error(tmp_path, capsys):
    assert export_main([str(tmp_path / "missing"), str(tmp_path / "out")]) == 2
    assert "error:" in capsys.readouterr().err
