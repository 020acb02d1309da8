"""Export a project scene for the official BuildNet3D nerfstudio dataparser.

``python -m dataset.buildnet3d_export SCENE OUT`` (or :func:`export_buildnet3d`) writes
the folder that EPFL-IMOS/buildnet3d's ``BuildNetDataParser`` reads
(``buildnet3d/data/buildnet_dataparser.py``; rules cited in docs/importing.md), so its
semantic-SDF model can be trained on our benchmark:

```
OUT/meta_data.json           width, height, scene_box.aabb, frames[] (rgb_path,
                             segmentation_path, camtoworld (OpenGL, 4x4), intrinsics (4x4),
                             depth_path, normals_path)
OUT/segmentation_data.json   {class name: [R, G, B]} in our id order (the dataparser's classes)
OUT/images/frame_{split}_{i:04d}.png      RGB
OUT/semantic/frame_{split}_{i:04d}.png    single-channel uint8 ids (ours; nerfstudio reads ids)
OUT/depths/frame_{split}_{i:04d}.png      uint16 millimetres (the dataparser's default unit)
OUT/normals/…                              copied when the scene has normal images
```

Only ``train`` and ``eval`` frames are exported (the dataparser splits by "train" /
"eval" in the file name and refuses any other name); ``ideal`` and ``multi`` views are
the 2D methods' and are left out. The folder is written atomically.
"""

from __future__ import annotations

import argparse
import shutil
import sys
from pathlib import Path

import numpy as np

from dataset.importers.buildnet3d.buildnet3d import write_atomically
from dataset.importers.buildnet3d.meta_data import BUILDNET3D_LAYOUT, write_meta_data
from envelope.atomic import write_json_atomic
from envelope.classes import CLASS_NAMES, SemanticClass
from envelope.protocols import EVAL_SPLIT, TRAIN_PROTOCOL
from envelope.scene_record import Frame, Scene
from envelope.scenes.images import read_rgb, write_depth_m, write_labels, write_rgb
from envelope.scenes.scene import read_scene
from envelope.scenes.scene_validation import read_frame_depth_m, read_frame_labels

EXPORT_SPLITS = (TRAIN_PROTOCOL, EVAL_SPLIT)
DEPTH_UNIT_M = 0.001
"""``BuildNetDataParserConfig.depth_unit_scale_factor`` (millimetres); depths beyond the
16-bit range (65.535 m) are written as 0, no depth."""
CLASS_COLOURS: dict[int, tuple[int, int, int]] = {
    # The BlenderProc renderer's colours of the same classes (generate.py:125-136).
    SemanticClass.BACKGROUND: (0, 0, 0), SemanticClass.WALL: (175, 200, 0),
    SemanticClass.WINDOW: (125, 0, 200), SemanticClass.ROOF: (175, 0, 200),
    SemanticClass.DOOR: (0, 200, 200), SemanticClass.OTHER: (0, 50, 200),
}


def export_buildnet3d(scene: Scene, out_dir: str | Path, *, overwrite: bool = False) -> Path:
    """Write ``scene``'s train and eval frames as a BuildNet3D dataparser folder.

    Raises
    ------
    ValueError
        The scene has no train or eval frame, frames of different sizes, or ``out_dir``
        exists and ``overwrite`` is false.
    """
    out_dir = Path(out_dir)
    frames = [f for f in scene.frames if f.split in EXPORT_SPLITS]
    if not frames:
        raise ValueError(f"{scene.root} has no train or eval frame to export")
    if out_dir.exists() and not overwrite:
        raise ValueError(f"{out_dir} exists; pass --overwrite to replace it")
    return write_atomically(out_dir, lambda tmp: _write(scene, frames, tmp), overwrite=True)


def _write(scene: Scene, frames: list[Frame], out: Path) -> None:
    for sub in ("images", "semantic", "depths"):
        (out / sub).mkdir(parents=True, exist_ok=True)
    exported = []
    for i, fr in enumerate(frames):
        name = f"frame_{fr.split}_{i:04d}.png"
        write_rgb(out / "images" / name, read_rgb(scene.path(fr.file_path)))
        labels = read_frame_labels(scene, fr)
        write_labels(out / "semantic" / name, labels)
        depth = None
        if fr.depth_file_path is not None:
            d = read_frame_depth_m(scene, fr).astype(np.float64)
            d[d > DEPTH_UNIT_M * np.iinfo(np.uint16).max] = 0.0
            write_depth_m(out / "depths" / name, d, DEPTH_UNIT_M)
            depth = f"depths/{name}"
        normals = None
        if fr.normal_file_path is not None:
            (out / "normals").mkdir(exist_ok=True)
            shutil.copyfile(scene.path(fr.normal_file_path), out / "normals" / name)
            normals = f"normals/{name}"
        exported.append(Frame(
            file_path=f"images/{name}", world_from_camera=fr.world_from_camera,
            intrinsics=fr.intrinsics, split=fr.split, semantic_file_path=f"semantic/{name}",
            depth_file_path=depth, normal_file_path=normals))
    copy = Scene(root=out, frames=tuple(exported), depth_unit_scale_factor=DEPTH_UNIT_M,
                 building=scene.building,
                 extra={k: v for k, v in scene.extra.items() if k == "scene_box"})
    write_meta_data(copy, out / "meta_data.json", layout=BUILDNET3D_LAYOUT)
    write_json_atomic(out / "segmentation_data.json",
                      {name: list(CLASS_COLOURS[i]) for i, name in enumerate(CLASS_NAMES)})


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m dataset.buildnet3d_export",
        description="Write a scene's train and eval frames as the folder the official "
                    "BuildNet3D nerfstudio dataparser reads (meta_data.json with camtoworld, "
                    "segmentation_data.json, images/, semantic/, depths/ named "
                    "frame_train_*/frame_eval_*). Train the official model with "
                    "`python buildnet3d/scripts/reconstruct.py --data OUT`.")
    parser.add_argument("scene", type=Path, help="a scene folder (with transforms.json)")
    parser.add_argument("out", type=Path, help="the folder to write")
    parser.add_argument("--overwrite", action="store_true", help="replace an existing OUT")
    args = parser.parse_args(argv)
    try:
        print(export_buildnet3d(read_scene(args.scene), args.out, overwrite=args.overwrite))
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
