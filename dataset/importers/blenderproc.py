"""Import the BuildNet3D BlenderProc generator's (and dataparser's) layout as project scenes.

``python -m dataset.generate --buildnet3d PATH --out DIR`` calls :func:`import_blenderproc`
when PATH holds this layout (:func:`find_scenes`): a folder with ``meta_data.json`` and
``images/`` and ``semantic/`` (the dataparser) or ``semantics/`` (the generator) beside it,
or a folder of such folders. One scene ``DIR/<folder name>`` per folder. The facts and
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
- facade ids: from geometry (:mod:`dataset.importers.depth_facades`), as this layout has no per-wall
  ground truth; no ``building.json`` is written (no truth to write).
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from dataset.core.camera import Intrinsics
from dataset.core.classes import SemanticClass
from dataset.core.protocols import EVAL_SPLIT, TRAIN_PROTOCOL, Split
from dataset.core.scene_record import Scene
from dataset.importers.buildnet3d import (
    ImportedView,
    facade_ids_from_walls,
    write_atomically,
    write_scene_views,
)
from dataset.importers.depth_facades import facades_from_depth
from dataset.scenes.labels import ClassMapping, class_mapping, read_remapped_labels

DEPTH_UNIT_M = 0.001
"""The generator writes depth as ``(depth * 1000).astype(uint16)``: millimetres."""
BLENDER_PIXEL_CENTRE_SHIFT = 0.5
"""Added to BlenderProc's cx, cy: its pixel centres are at integers, ours at +0.5."""


def find_scenes(path: str | Path) -> list[Path]:
    """The BlenderProc-layout folders at ``path``: itself, or its sub-folders (sorted)."""
    path = Path(path)
    if _is_scene(path):
        return [path]
    if not path.is_dir():
        return []
    return sorted(p for p in path.iterdir() if p.is_dir() and _is_scene(p))


def import_blenderproc(path: str | Path, out_root: str | Path, *,
                       overwrite: bool = False) -> list[Path]:
    """Import every BlenderProc-layout folder at ``path`` into ``out_root/<folder name>``.

    Each scene is written atomically (:func:`dataset.buildnet3d.write_atomically`); an
    existing scene is kept unless ``overwrite``.

    Raises
    ------
    ValueError
        ``path`` holds no such folder, or a file is missing or malformed.
    """
    scenes = find_scenes(path)
    if not scenes:
        raise ValueError(f"{path} holds no BlenderProc-layout folder (meta_data.json with "
                         "images/ and semantic/ or semantics/ beside it)")
    out_root = Path(out_root)
    return [write_atomically(out_root / d.name, lambda tmp, d=d: import_scene(d, tmp),
                             overwrite=overwrite) for d in scenes]


def import_scene(folder: Path, out_dir: Path) -> Scene:
    """Write the BlenderProc-layout ``folder`` as a scene in ``out_dir``; return it."""
    meta = _read_json(folder / "meta_data.json")
    mapping = scene_class_mapping(folder)
    masks = folder / "semantic" if (folder / "semantic").is_dir() else folder / "semantics"
    try:
        width, height = int(meta["width"]), int(meta["height"])
        frames = list(meta["frames"])
    except (KeyError, TypeError, ValueError) as exc:
        raise ValueError(f"{folder / 'meta_data.json'} lacks width, height or frames: "
                         f"{exc!r}") from None
    if not frames:
        raise ValueError(f"{folder / 'meta_data.json'} has no frames")
    read = [_read_frame(folder, masks, fr, width, height, mapping) for fr in frames]
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
    seg = _read_json(path)
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


def _read_frame(folder: Path, masks: Path, fr: dict[str, Any], width: int, height: int,
                mapping: ClassMapping) -> ImportedView:
    try:
        rgb = str(fr["rgb_path"])
        generator = "camera_to_world" in fr
        pose = np.asarray(fr["camera_to_world"] if generator else fr["camtoworld"], float)
        k = np.asarray(fr["intrinsics"], dtype=np.float64)
        segmentation = str(fr["segmentation_path"])
    except (KeyError, TypeError, ValueError) as exc:
        raise ValueError(f"{folder / 'meta_data.json'}: frame {fr.get('rgb_path', '?')!r} "
                         f"lacks {exc!r} (rgb_path, segmentation_path, camtoworld or "
                         "camera_to_world, intrinsics)") from None
    if pose.shape == (3, 4):
        pose = np.vstack([pose, [0.0, 0.0, 0.0, 1.0]])
    if pose.shape != (4, 4) or k.shape not in ((3, 3), (4, 4)):
        raise ValueError(f"frame {rgb}: pose must be 4x4 and intrinsics 3x3 or 4x4, got "
                         f"{pose.shape} and {k.shape}")
    shift = BLENDER_PIXEL_CENTRE_SHIFT if generator else 0.0
    intr = Intrinsics(float(k[0, 0]), float(k[1, 1]), float(k[0, 2]) + shift,
                      float(k[1, 2]) + shift, width, height)
    try:
        labels = read_remapped_labels(masks / segmentation, mapping)
    except ValueError as exc:
        raise ValueError(f"{masks / segmentation}: {exc}") from None
    stem = Path(rgb).stem
    depth_file = (folder / fr["depth_path"] if fr.get("depth_path")
                  else folder / "depths" / f"{stem}_depth.png")
    return ImportedView(stem, folder / "images" / rgb, intr, pose, split_from_name(Path(rgb).name),
                        labels, read_mm_depth_m(depth_file, labels),
                        np.zeros(labels.shape, dtype=np.int32))


def _is_scene(folder: Path) -> bool:
    return ((folder / "meta_data.json").is_file() and (folder / "images").is_dir()
            and ((folder / "semantic").is_dir() or (folder / "semantics").is_dir()))


def _read_json(path: Path) -> Any:
    if not path.is_file():
        raise ValueError(f"{path} does not exist")
    try:
        return json.loads(path.read_text())
    except json.JSONDecodeError as exc:
        raise ValueError(f"{path} is not valid JSON: {exc}") from None
