"""A degraded copy of a scene folder: same layout, inputs degraded, truth untouched.

Files that a degradation does not change (and the truth: ``building.json``,
``mesh.ply``, ``instances/``) are hard links to the original (copies across
file systems, :func:`dataset.scenes.links.link_tree`, which the segmenter's mask copies share too);
changed images are written as new files, so the original scene is never
modified. ``transforms.json`` records the specs and the source under
``degradation``, which is how a rerun recognises a finished copy.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from dataset.degrade.depth_noise import noisy_depth_m
from dataset.degrade.masks import (
    bleed_labels,
    dilate_windows,
    erode_windows,
    false_windows,
    mask_noise,
    miss_windows,
)
from dataset.degrade.occluders import place_occluders, render_occluders
from dataset.degrade.poses import pose_noise
from dataset.degrade.spec import DegradeSpec
from dataset.scenes.links import link_tree
from envelope.atomic import atomic_directory
from envelope.mesh import read_labelled_ply
from envelope.scene_record import Frame, Scene
from envelope.scenes.images import (
    read_depth_m,
    read_labels,
    read_normals,
    read_rgb,
    write_depth_m,
    write_labels,
    write_normals,
    write_rgb,
)
from envelope.scenes.scene import read_scene, write_transforms

RECORD_KEY = "degradation"
_MASK_FNS = {
    "mask_erode": lambda lab, s, rng: erode_windows(lab, int(s)),
    "mask_dilate": lambda lab, s, rng: dilate_windows(lab, int(s)),
    "mask_miss": miss_windows,
    "mask_false": false_windows,
    "mask_bleed": lambda lab, s, rng: bleed_labels(lab, int(s), rng),
    "mask_noise": mask_noise,
}


def degradation_record(specs: tuple[DegradeSpec, ...], source: Scene) -> dict[str, Any]:
    """What ``transforms.json`` of a degraded copy records: specs, source folder and its
    generator record (so a regenerated source invalidates the copy)."""
    return {
        "specs": [s.to_json() for s in specs],
        "source": str(source.root.resolve()),
        "source_generator": source.extra.get("generator"),
    }


def degrade_scene(source_dir: str | Path, out_root: str | Path,
                  specs: tuple[DegradeSpec, ...]) -> Path:
    """Write ``out_root / <scene name>``, the scene with ``specs`` applied; return its path.

    A finished copy with the same record is reused. Raises ``ValueError`` if the
    source is not a scene folder or lacks what a degradation needs (``mesh.ply``
    for occluders).
    """
    source = read_scene(source_dir)
    record = degradation_record(specs, source)
    out = Path(out_root) / Path(source_dir).name
    if _finished(out, record):
        return out
    active = tuple(s for s in specs if s.severity > 0)
    with atomic_directory(out) as tmp:
        link_tree(Path(source_dir), tmp)
        occluders = _occluders_of(source, active)
        frames = [_degrade_frame(source, tmp, i, fr, active, occluders)
                  for i, fr in enumerate(source.frames)]
        extra = {**source.extra, RECORD_KEY: record}
        write_transforms(tmp, replace(source, root=tmp, frames=tuple(frames), extra=extra))
    return out


def _degrade_frame(source: Scene, tmp: Path, index: int, fr: Frame,
                   specs: tuple[DegradeSpec, ...], occluders) -> Frame:
    names = {s.name for s in specs}
    unit = source.depth_unit_scale_factor
    labels = (read_labels(source.path(fr.semantic_file_path))
              if fr.semantic_file_path is not None else None)
    depth = (read_depth_m(source.path(fr.depth_file_path), unit)
             if fr.depth_file_path is not None else None)
    changed: set[str] = set()
    if occluders is not None and labels is not None:
        normals = (read_normals(source.path(fr.normal_file_path))
                   if fr.normal_file_path is not None else None)
        rgb, depth, labels, normals = render_occluders(
            occluders, fr.intrinsics, fr.world_from_camera, depth,
            read_rgb(source.path(fr.file_path)), labels, normals)
        write_rgb(tmp / fr.file_path, rgb)
        if normals is not None:
            write_normals(tmp / fr.normal_file_path, normals)
        changed |= {"labels", "depth"}
    glass = labels
    for spec in specs:
        if spec.name in _MASK_FNS and labels is not None:
            labels = _MASK_FNS[spec.name](labels, spec.severity, spec.rng(index))
            changed.add("labels")
    if "depth_noise" in names and depth is not None and glass is not None:
        spec = next(s for s in specs if s.name == "depth_noise")
        depth = noisy_depth_m(depth, glass, spec.severity, spec.rng(index))
        changed.add("depth")
    if "labels" in changed:
        write_labels(tmp / fr.semantic_file_path, labels)
    if "depth" in changed and depth is not None:
        write_depth_m(tmp / fr.depth_file_path, depth, unit)
    if "pose" in names:
        spec = next(s for s in specs if s.name == "pose")
        fr = replace(fr, world_from_camera=pose_noise(fr.world_from_camera, spec.severity,
                                                      spec.rng(index)))
    return fr


def _occluders_of(source: Scene, specs: tuple[DegradeSpec, ...]):
    spec = next((s for s in specs if s.name == "occluders"), None)
    if spec is None:
        return None
    mesh_path = source.path("mesh.ply")
    if not mesh_path.is_file():
        raise ValueError(f"occluders need the scene's mesh.ply to stand in front of its "
                         f"facades; {source.root} has none")
    cameras = np.array([fr.world_from_camera[:3, 3] for fr in source.frames])
    return place_occluders(read_labelled_ply(mesh_path), spec.severity, cameras,
                           spec.rng(-1 % 2**31))


def _finished(out: Path, record: dict[str, Any]) -> bool:
    tf = out / "transforms.json"
    if not tf.is_file():
        return False
    try:
        return json.loads(tf.read_text()).get(RECORD_KEY) == json.loads(json.dumps(record))
    except json.JSONDecodeError:
        return False
