"""The BuildNet3D BlenderProc generator's and dataparser's layouts, written from a building
rendered with dataset.rendering.render exactly as bproc_generator/render/generate.py and
buildnet_dataparser.py have them (tests/dataset/importers/test_blenderproc.py imports them
back; tests/metrics/test_official_compare.py runs every method on them)."""

from __future__ import annotations

import json

import cv2
import numpy as np

from dataset.rendering.render import render_view
from envelope.camera import Intrinsics, look_at
from envelope.classes import SemanticClass as C
from envelope.scenes.labels import class_mapping

RENDERER = class_mapping("renderer")
BPROC_ID = {C.BACKGROUND: 0, C.WALL: 1, C.DOOR: 2, C.WINDOW: 3, C.ROOF: 4, C.OTHER: 5}
BACKGROUND_DEPTH_M = 65504.0  # BlenderProc's depth where no object is hit
SIZE = (96, 72)
AZIMUTHS_DEG = (-90, -45, 0, 45, 90, 135, 180, 225)  # head-on to facades 1, 2, 3, 4 at 0, 2, 4, 6


def _bproc_ids(labels: np.ndarray) -> np.ndarray:
    lut = np.zeros(256, np.uint8)
    for ours, theirs in BPROC_ID.items():
        lut[ours] = theirs
    return lut[labels]


def _write_png(path, img) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    assert cv2.imwrite(str(path), img[..., ::-1] if img.ndim == 3 else img)


def write_blenderproc_output(root, building, layout: str = "generator"):
    """The generator's files (``layout="generator"``: images/0000.png, colour masks in
    semantics/0000_mask.png, depths/0000_depth.png = (depth * 1000).astype(uint16) with the
    65504 m background, normals/, meta_data.json with camera_to_world and BlenderProc's 3x3
    K, no segmentation_data.json), or the dataparser's (``"dataparser"``: frame_train_/
    frame_eval_ names, single-channel ids in semantic/, camtoworld, segmentation_data.json
    {name: RGB}, depth_path and normals_path keys). Returns the rendered truth per view."""
    intr = Intrinsics.from_fov(*SIZE, 60.0)
    k = intr.K.copy()
    if layout == "generator":  # get_intrinsics_as_K_matrix: cx = (W - 1) / 2
        k[:2, 2] -= 0.5
    frames, truth = [], []
    for i, az in enumerate(np.deg2rad(AZIMUTHS_DEG)):
        eye = np.array([np.cos(az), np.sin(az), 0.0]) * 30.0 + [0.0, 0.0, 8.0]
        pose = look_at(eye, np.array([0.0, 0.0, 4.5]))
        gt, rgb = render_view(building.mesh, intr, pose)
        ids = _bproc_ids(gt.labels)
        depth = (np.where(gt.depth_z_m > 0, gt.depth_z_m, BACKGROUND_DEPTH_M)
                 .astype(np.float32) * 1000).astype(np.uint16)
        normal = (np.clip(gt.normals_world, 0, 1) * 255).astype(np.uint8)
        if layout == "generator":
            stem, seg_name = f"{i:04d}", f"{i:04d}_mask.png"
            _write_png(root / "semantics" / seg_name,
                       np.asarray(RENDERER.colours, np.uint8)[ids])
            frame = {"rgb_path": f"{stem}.png", "segmentation_path": seg_name,
                     "camera_to_world": pose.tolist(), "intrinsics": k.tolist()}
        else:
            stem = f"frame_{'eval' if i in (1, 5) else 'train'}_{i:04d}"
            seg_name = f"{stem}.png"
            _write_png(root / "semantic" / seg_name, ids)
            frame = {"rgb_path": f"{stem}.png", "segmentation_path": seg_name,
                     "camtoworld": pose.tolist(), "intrinsics": k.tolist(),
                     "depth_path": f"depths/{stem}_depth.png",
                     "normals_path": f"normals/{stem}_normal.png"}
        _write_png(root / "images" / f"{stem}.png", rgb)
        _write_png(root / "depths" / f"{stem}_depth.png", depth)
        _write_png(root / "normals" / f"{stem}_normal.png", normal)
        frames.append(frame)
        truth.append(gt)
    meta = {"camera_model": "OPEN_CV", "width": SIZE[0], "height": SIZE[1],
            "has_mono_prior": False, "has_foreground_mask": False,
            "has_sparse_sfm_points": False,
            "scene_box": {} if layout == "generator" else {"aabb": [[-1, -1, -1], [1, 1, 1]]},
            "frames": frames}
    (root / "meta_data.json").write_text(json.dumps(meta, indent=4))
    if layout == "dataparser":
        seg = {n: list(c) for n, c in zip(RENDERER.names[:6], RENDERER.colours[:6])}
        (root / "segmentation_data.json").write_text(json.dumps(seg, indent=4))
    return truth

