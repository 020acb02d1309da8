"""A scene copy whose semantic images are a segmenter's predictions from the RGB.

Every frame's semantic image is replaced by ``segmenter(rgb)`` (a frame without one
gets ``semantics/<image name>.png``); every other file, the truth included, is a hard
link to the original (:func:`dataset.scenes.links.link_tree`), so the source is
never modified. Given ``splits``, only the frames of those splits are segmented and
kept: the others leave the copy's ``transforms.json`` and their exact semantic and
instance images leave the copy (no exact mask is left for a method to find).
The segmenter reads the RGB images and nothing else: not the exact masks, not
``building.json``, ``mesh.ply`` or ``instances/``.

The copy's ``transforms.json`` records, under :data:`RECORD_KEY`, the provenance of its
masks: the segmenter's name and identity (weights and code fingerprints, or a plugin's
entry point and version), the fingerprint of the source's ``transforms.json`` and the
library versions. A finished copy with the same record is reused; a copy is written
atomically, so a refused prediction (wrong shape, dtype, class ids) leaves nothing.
"""

from __future__ import annotations

import json
from collections.abc import Collection
from dataclasses import replace
from pathlib import Path

from tqdm import tqdm

from dataset.scenes.links import link_tree
from envelope.atomic import atomic_directory
from envelope.classes import CLASS_NAMES
from envelope.photo_io import read_photo_rgb
from envelope.provenance import (
    Provenance,
    file_fingerprint,
    make_provenance,
    provenance_changes,
)
from envelope.scene_record import Frame
from envelope.scenes.images import write_labels
from envelope.scenes.scene import read_scene, write_transforms
from segment.segmenter import Segmenter, segment_rgb

RECORD_KEY = "predicted_masks"
SEMANTICS_FOLDER = "semantics"


def masks_provenance(segmenter: Segmenter, source_dir: str | Path,
                     splits: Collection[str] | None = None) -> Provenance:
    """The record a mask copy of ``source_dir`` made by ``segmenter`` carries (``splits``:
    the frame splits it holds, ``None``: every frame)."""
    transforms = Path(source_dir) / "transforms.json"
    return make_provenance(
        {"segmenter": segmenter.name, **segmenter.identity,
         "splits": "all" if splits is None else sorted(set(splits))},
        modules=("segment.scene_masks",),
        inputs={"scene": file_fingerprint(transforms) if transforms.is_file() else "absent"},
        libraries=("numpy", "opencv-contrib-python-headless"),
    )


def predicted_scene(source_dir: str | Path, out_root: str | Path, segmenter: Segmenter, *,
                    splits: Collection[str] | None = None, progress: bool = True) -> Path:
    """Write ``out_root / <scene name>``: the scene with the segmenter's masks; return it.

    ``splits``: segment and keep only the frames of these splits (``"ideal"``,
    ``"multi"``, ``"train"``, ``"eval"``; ``None``: every frame). A finished copy with the
    same provenance (segmenter, source, splits) is reused.

    Raises
    ------
    ValueError
        If the source is not a valid scene folder (an RGB image of another size than its
        frame declares included) or the segmenter's answer is refused
        (:func:`segment.segmenter.segment_rgb`); nothing is written then.
    """
    source_dir = Path(source_dir)
    source = read_scene(source_dir)
    record = masks_provenance(segmenter, source_dir, splits)
    out = Path(out_root) / source_dir.name
    if stored_masks_changes(out, record) == []:
        return out
    kept = [fr for fr in source.frames if splits is None or fr.split in splits]
    with atomic_directory(out) as tmp:
        link_tree(source_dir, tmp)
        for fr in source.frames:
            if splits is not None and fr.split not in splits:
                for rel in (fr.semantic_file_path, fr.instance_file_path):
                    if rel is not None:
                        (tmp / rel).unlink(missing_ok=True)
        frames = tuple(
            _predict_frame(source.root, tmp, fr, segmenter)
            for fr in tqdm(kept, desc=f"masks {source_dir.name}", unit="frame",
                           leave=False, disable=not progress))
        extra = {**source.extra, RECORD_KEY: record.to_json_dict()}
        write_transforms(tmp, replace(source, root=tmp, frames=frames,
                                      semantic_classes=CLASS_NAMES, extra=extra))
    return out


def stored_masks_changes(scene_dir: Path, current: Provenance) -> list | None:
    """How a mask copy's record differs from ``current`` (``[]``: reusable), or ``None``
    if ``scene_dir`` holds no finished mask copy."""
    tf = scene_dir / "transforms.json"
    if not tf.is_file():
        return None
    try:
        stored = json.loads(tf.read_text()).get(RECORD_KEY)
        return provenance_changes(Provenance.from_json_dict(stored), current)
    except (json.JSONDecodeError, ValueError, TypeError, AttributeError):
        return None


def _predict_frame(source_root: Path, tmp: Path, fr: Frame, segmenter: Segmenter) -> Frame:
    rgb = read_photo_rgb(source_root / fr.file_path)
    size = (fr.intrinsics.height, fr.intrinsics.width)
    if rgb.shape[:2] != size:
        raise ValueError(f"{source_root / fr.file_path} is {rgb.shape[1]}x{rgb.shape[0]} px but "
                         f"its frame declares {size[1]}x{size[0]}; re-export the scene")
    labels = segment_rgb(segmenter, rgb)
    relative = fr.semantic_file_path or f"{SEMANTICS_FOLDER}/{Path(fr.file_path).stem}.png"
    write_labels(tmp / relative, labels)  # a new file: the hard link to the source is replaced
    return replace(fr, semantic_file_path=relative)
