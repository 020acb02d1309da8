"""The BuildNet3D BlenderProc generator's (and dataparser's) layout as a source of scenes.

``python -m dataset.generate --buildnet3d PATH --out DIR`` reads PATH with
:data:`BLENDERPROC_SOURCE` when it holds this layout (:func:`find_scene_folders`): a folder with
``meta_data.json`` and ``images/`` and ``semantic/`` (the dataparser) or ``semantics/`` (the
generator) beside it, or a folder of such folders. One scene ``DIR/<folder name>`` per folder
(:func:`import_scene` writes it). The facts and
where they come from (EPFL-IMOS/buildnet3d, file:line) are in docs/importing.md.

- labels: colour masks (the generator) or single-channel ids (the dataparser), ids 0
  background, 1 wall, 2 door, 3 window, 4 roof, 5 chimney (…9), named and coloured by
  ``segmentation_data.json`` when there is one; remapped to ours
  (:func:`dataset.labels.read_remapped_labels`); an unknown id or colour is an error;
- depth: uint16 millimetres ``depths/{stem}_depth.png`` (or the frame's ``depth_path``);
  background pixels hold BlenderProc's 65504 m background wrapped to 16 bits, so depth is
  taken only where the labels show something;
- poses: ``camera_to_world`` (the generator) or ``camtoworld`` (the dataparser), Blender
  / nerfstudio OpenGL cameras in a z-up world in metres: used as they are;
- intrinsics: 3x3 (or 4x4) K; BlenderProc's K puts pixel centres at integers
  (cx = (W - 1) / 2), ours at +0.5, so the generator's cx, cy gain half a pixel;
- split: from the file name as the dataparser decides it ("train" / "eval" in the
  name); names with neither (the generator's ``0000.png``) are ``train``;
- facade ids: from geometry (:mod:`dataset.importers.buildnet3d.depth_facades`), as this layout has
no per-wall
  ground truth; no ``building.json`` is written (no truth to write).
"""

from __future__ import annotations

from dataclasses import replace
from functools import partial
from pathlib import Path

import cv2
import numpy as np

from dataset.importers.buildnet3d.buildnet3d import (
    ImportedView,
    facade_ids_from_walls,
    write_scene_views,
)
from dataset.importers.buildnet3d.depth_facades import facades_from_depth
from dataset.importers.buildnet3d.meta_data_file import (
    META_DATA_FILE,
    MetaData,
    MetaDataFrame,
    read_json_file,
    read_meta_data_file,
)
from dataset.importers.source import NoOptions, SceneEntry, Source
from envelope.classes import SemanticClass
from envelope.protocols import EVAL_SPLIT, TRAIN_PROTOCOL, Split
from envelope.scene_record import Scene
from envelope.scenes.labels import ClassMapping, class_mapping, read_remapped_labels

DEPTH_UNIT_M = 0.001
"""The generator writes depth as ``(depth * 1000).astype(uint16)``: millimetres."""
BLENDER_PIXEL_CENTRE_SHIFT = 0.5
"""Added to BlenderProc's cx, cy: its pixel centres are at integers, ours at +0.5."""


def find_scene_folders(path: str | Path) -> list[Path]:
    """The BlenderProc-layout folders at ``path``: itself, or its sub-folders (sorted)."""
    path = Path(path)
    if _is_scene(path):
        return [path]
    if not path.is_dir():
        return []
    return sorted(p for p in path.iterdir() if p.is_dir() and _is_scene(p))


def read_blenderproc(path: str | Path, options: NoOptions) -> tuple[SceneEntry, ...]:
    """One scene entry per BlenderProc-layout folder at ``path``, named by the folder.

    Raises
    ------
    ValueError
        ``path`` holds no such folder.
    """
    scenes = find_scene_folders(path)
    if not scenes:
        raise ValueError(f"{path} holds no BlenderProc-layout folder (meta_data.json with "
                         "images/ and semantic/ or semantics/ beside it)")
    return tuple(SceneEntry(d.name, partial(import_scene, d)) for d in scenes)


def import_scene(folder: Path, out_dir: Path) -> Scene:
    """Write the BlenderProc-layout ``folder`` as a scene in ``out_dir``; return it.

    Raises
    ------
    ValueError
        A file is missing or malformed (the message names it).
    """
    meta = read_meta_data_file(folder / META_DATA_FILE)
    mapping = scene_class_mapping(folder)
    masks = folder / "semantic" if (folder / "semantic").is_dir() else folder / "semantics"
    read = [_read_frame(folder, masks, meta, fr, mapping) for fr in meta.frames]
    walls = facades_from_depth([(v.labels, v.depth_z_m, v.intrinsics, v.world_from_camera)
                                for v in read])
    views = [replace(v, facade_ids=facade_ids_from_walls(
        v.labels, v.depth_z_m, v.intrinsics, v.world_from_camera, walls)) for v in read]
    return write_scene_views(out_dir, views, [w["normal"] for w in walls], {
        "source": "BuildNet3D BlenderProc", "source_folder": folder.name,
        "facades_from": "geometry: depth of the wall pixels (no per-wall truth in the layout)",
    })


def scene_class_mapping(folder: Path) -> ClassMapping:
    """The classes of the folder's masks: ``segmentation_data.json`` ({name: RGB}, ids in
    its order) checked against the BlenderProc renderer's (or the project's own export),
    or the renderer's classes when the file is absent (the generator writes none)."""
    renderer = class_mapping("renderer")
    path = folder / "segmentation_data.json"
    if not path.is_file():
        return renderer
    seg = read_json_file(path)
    if not isinstance(seg, dict) or not seg:
        raise ValueError(f"{path} must map class names to RGB colours")
    names = tuple(seg)
    try:
        colours = tuple(tuple(int(x) for x in c) for c in seg.values())
    except (TypeError, ValueError):
        raise ValueError(f"{path}: every class needs an RGB colour, got {list(seg.values())}"
                         ) from None
    for base in (renderer, class_mapping("envelope_bench")):
        if names != base.names[: len(names)]:
            continue
        if base.colours is not None and colours != base.colours[: len(names)]:
            raise ValueError(f"{path} gives the {base.source!r} classes other colours "
                             f"({list(colours)}) than {list(base.colours[: len(names)])}")
        return replace(base, names=names, to_ours=base.to_ours[: len(names)], colours=colours)
    raise ValueError(
        f"{path} lists classes {list(names)}, which are neither the BlenderProc renderer's "
        f"({', '.join(renderer.names)}) nor the project's, in that order; remap the masks "
        "to one of them")


def read_mm_depth_m(path: Path, labels: np.ndarray) -> np.ndarray:
    """(H, W) float32 z-depth (m) of a uint16 millimetre PNG; 0 where ``labels`` (ours)
    show background (BlenderProc's background depth wraps to a plausible 33.536 m)."""
    if not path.is_file():
        raise ValueError(f"depth image {path} does not exist (the BlenderProc generator "
                         "writes depths/<stem>_depth.png; the dataparser names it depth_path)")
    img = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    if img is None or img.ndim != 2 or img.dtype != np.uint16:
        raise ValueError(f"{path} is not a single-channel 16-bit PNG of millimetres")
    if img.shape != labels.shape:
        raise ValueError(f"{path} is {img.shape[1]}x{img.shape[0]} px, its mask "
                         f"{labels.shape[1]}x{labels.shape[0]}")
    depth = img.astype(np.float32) * np.float32(DEPTH_UNIT_M)
    depth[labels == SemanticClass.BACKGROUND] = 0.0
    return depth


def split_from_name(name: str) -> Split:
    """``train`` or ``eval`` as the dataparser reads a file name; ``train`` if neither."""
    if TRAIN_PROTOCOL in name:
        return TRAIN_PROTOCOL
    return EVAL_SPLIT if EVAL_SPLIT in name else TRAIN_PROTOCOL


def _read_frame(folder: Path, masks: Path, meta: MetaData, fr: MetaDataFrame,
                mapping: ClassMapping) -> ImportedView:
    if fr.segmentation_path is None:
        raise ValueError(f"{meta.file}: frame {fr.rgb_path!r} lacks segmentation_path")
    generator = fr.pose_key == "camera_to_world"
    intr = meta.intrinsics(fr, BLENDER_PIXEL_CENTRE_SHIFT if generator else 0.0)
    segmentation = masks / fr.segmentation_path
    try:
        labels = read_remapped_labels(segmentation, mapping)
    except ValueError as exc:
        raise ValueError(f"{segmentation}: {exc}") from None
    stem = Path(fr.rgb_path).stem
    depth_file = (folder / fr.depth_path if fr.depth_path
                  else folder / "depths" / f"{stem}_depth.png")
    return ImportedView(stem, folder / "images" / fr.rgb_path, intr, fr.camera_to_world,
                        split_from_name(Path(fr.rgb_path).name), labels,
                        read_mm_depth_m(depth_file, labels),
                        np.zeros(labels.shape, dtype=np.int32))


def _is_scene(folder: Path) -> bool:
    return ((folder / META_DATA_FILE).is_file() and (folder / "images").is_dir()
            and ((folder / "semantic").is_dir() or (folder / "semantics").is_dir()))


BLENDERPROC_SOURCE = Source(
    name="buildnet3d-blenderproc", flag="--buildnet3d",
    help="a BlenderProc generator or dataparser folder of the official BuildNet3D "
         "(meta_data.json with images/ and semantic/ or semantics/ beside it) or a folder of "
         "them: one scene per folder, as rendered",
    detect=lambda path: bool(find_scene_folders(path)), read=read_blenderproc,
)
