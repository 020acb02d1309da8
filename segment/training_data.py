"""The segmenter's training frames: which scenes, the split by building, and batches.

Only buildings that are never evaluated may be trained on: a scene whose generator
record names an evaluated preset (every preset but ``segtrain``) is refused. The
buildings are split by name (the same building rendered at two resolutions lands on
the same side): every ``val_every``-th name in sorted order is a validation building,
used to pick the best weights during training and never trained on.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch
from tqdm import tqdm

from dataset.presets import PRESETS, preset_recipes
from envelope.classes import NUM_CLASSES
from envelope.provenance import file_fingerprint
from envelope.scene_record import Frame, Scene
from envelope.scenes.images import read_rgb
from envelope.scenes.scene import find_scene_folders, read_scene
from envelope.scenes.scene_validation import read_frame_labels
from segment.augment import IGNORE_LABEL, AugmentConfig, augment_frame
from segment.evaluate import evenly_spaced
from segment.segmenter import scale_to_long_side

TRAINING_PRESET = "segtrain"
EVALUATED_PRESETS: tuple[str, ...] = tuple(p for p in PRESETS if p != TRAINING_PRESET)


@dataclass(frozen=True)
class TrainingScene:
    """One scene to train or validate on: its frames with masks, and its record."""

    scene: Scene
    frames: tuple[Frame, ...]
    record: dict[str, Any]

    @property
    def name(self) -> str:
        return self.scene.root.name

    def rgb_and_labels(self, frame: Frame) -> tuple[np.ndarray, np.ndarray]:
        """(H, W, 3) uint8 RGB and (H, W) uint8 exact class ids of one frame."""
        return read_rgb(self.scene.path(frame.file_path)), read_frame_labels(self.scene, frame)

    def labels(self, frame: Frame) -> np.ndarray:
        """(H, W) uint8 exact class ids of one frame."""
        return read_frame_labels(self.scene, frame)


def load_training_scenes(folders: Sequence[Path]) -> list[TrainingScene]:
    """Every scene of ``folders`` (each a scene folder or a folder of them).

    Raises
    ------
    ValueError
        If a folder holds no scene, a scene has no masks, or a scene belongs to an
        evaluated preset.
    """
    scenes = []
    for folder in folders:
        try:
            dirs = find_scene_folders(folder, with_images=True)
        except ValueError as exc:
            raise ValueError(f"{exc} (the training buildings: `python -m dataset.generate "
                             f"--preset {TRAINING_PRESET} --out {folder}`)") from exc
        scenes += [_training_scene(read_scene(d)) for d in dirs]
    return scenes


def split_by_building(scenes: Sequence[TrainingScene], val_every: int
                      ) -> tuple[list[TrainingScene], list[TrainingScene]]:
    """(train, validation): a building is for validation if its rank among the sorted
    building names is ``val_every - 1`` modulo ``val_every`` (0: no validation)."""
    names = sorted({s.name for s in scenes})
    val_names = {n for i, n in enumerate(names) if val_every and i % val_every == val_every - 1}
    return ([s for s in scenes if s.name not in val_names],
            [s for s in scenes if s.name in val_names])


def class_weights(scenes: Sequence[Any], rng: np.random.Generator,
                  frames: int = 200) -> np.ndarray:
    """(NUM_CLASSES,) loss weights ``sqrt(median frequency / frequency)`` measured on
    ``frames`` random training masks (clipped to [0.1, 10]; 1 for an absent class).
    ``scenes``: training scenes or real-photo sources (anything with ``frames`` and
    ``labels(frame)``; ids of :data:`IGNORE_LABEL` are not counted)."""
    pairs = [(s, f) for s in scenes for f in s.frames]
    counts = np.zeros(NUM_CLASSES)
    for i in rng.choice(len(pairs), size=min(frames, len(pairs)), replace=False):
        scene, frame = pairs[i]
        labels = scene.labels(frame)
        counts += np.bincount(labels.ravel(), minlength=NUM_CLASSES)[:NUM_CLASSES]
    present = counts > 0
    freq = counts / counts.sum()
    weights = np.ones(NUM_CLASSES)
    weights[present] = np.sqrt(np.median(freq[present]) / freq[present])
    return np.clip(weights, 0.1, 10.0)


def sample_batch(scenes: Sequence[Any], batch: int, config: AugmentConfig,
                 rng: np.random.Generator) -> tuple[torch.Tensor, torch.Tensor]:
    """A batch of augmented crops from random frames of random scenes (training scenes or
    real-photo sources: anything with ``frames`` and ``rgb_and_labels(frame)``).

    Returns ``Float[Tensor, "B 3 S S"]`` RGB in [0, 1] (channels-last memory) and
    ``Long[Tensor, "B S S"]`` labels (:data:`IGNORE_LABEL` where there is none).
    """
    xs, ys = [], []
    for _ in range(batch):
        scene = scenes[rng.integers(len(scenes))]
        rgb, labels = scene.rgb_and_labels(scene.frames[rng.integers(len(scene.frames))])
        x, y = augment_frame(rgb, labels, config, rng)
        xs.append(x)
        ys.append(y)
    x = torch.from_numpy(np.stack(xs)).permute(0, 3, 1, 2)
    return x.contiguous(memory_format=torch.channels_last), torch.from_numpy(np.stack(ys))


@dataclass(frozen=True)
class PreloadedSource:
    """The frames of a training scene or real-photo source, read once and kept in memory
    at a network's working scale: ``frames`` are indices into ``rgbs`` and ``label_maps``;
    ``name`` and ``record`` are the source's."""

    name: str
    frames: tuple[int, ...]
    record: dict[str, Any]
    rgbs: tuple[np.ndarray, ...]
    label_maps: tuple[np.ndarray, ...]

    def rgb_and_labels(self, frame: int) -> tuple[np.ndarray, np.ndarray]:
        """(h, w, 3) uint8 RGB and (h, w) uint8 class ids at the working scale."""
        return self.rgbs[frame], self.label_maps[frame]

    def labels(self, frame: int) -> np.ndarray:
        """(h, w) uint8 class ids at the working scale."""
        return self.label_maps[frame]


def preload(sources: Sequence[Any], long_side_px: int | None, frames_per_source: int = 0,
            progress: bool = True) -> list[PreloadedSource]:
    """Each of ``sources`` (training scenes or real-photo sources) read once, every frame
    scaled to ``long_side_px`` (``None``: as it is;
    :func:`segment.segmenter.scale_to_long_side`), at most ``frames_per_source`` evenly
    spaced frames of each (0: all), so that a training step decodes nothing."""
    out = []
    for source in tqdm(sources, desc="read training frames", unit="source",
                       disable=not progress):
        rgbs, label_maps = [], []
        for frame in evenly_spaced(source.frames, frames_per_source or None):
            rgb, labels = source.rgb_and_labels(frame)
            rgbs.append(scale_to_long_side(rgb, long_side_px))
            label_maps.append(scale_to_long_side(labels, long_side_px, labels=True))
        out.append(PreloadedSource(source.name, tuple(range(len(rgbs))),
                                   {**source.record, "frames_read": len(rgbs)},
                                   tuple(rgbs), tuple(label_maps)))
    return out


def _training_scene(scene: Scene) -> TrainingScene:
    generator = scene.extra.get("generator") or {}
    inputs = (generator.get("provenance") or {}).get("inputs") or {}
    preset, recipe = inputs.get("preset"), inputs.get("recipe")
    if preset in EVALUATED_PRESETS:
        raise ValueError(f"{scene.root} is a building of the '{preset}' preset, which is "
                         f"evaluated: the segmenter must never train on it; render the "
                         f"training buildings with `python -m dataset.generate --preset "
                         f"{TRAINING_PRESET}`")
    frames = tuple(f for f in scene.frames if f.semantic_file_path is not None)
    if not frames:
        raise ValueError(f"{scene.root} has no semantic masks to train on")
    seeds = {r.id: r.seed for r in preset_recipes(preset)} if preset in PRESETS else {}
    record = {
        "scene": scene.root.name, "folder": str(scene.root.parent), "preset": preset,
        "recipe": recipe, "recipe_seed": seeds.get(recipe), "render_seed": inputs.get("seed"),
        "resolution": scene.frames[0].intrinsics.width, "frames": len(frames),
        "transforms": file_fingerprint(scene.path("transforms.json")),
    }
    return TrainingScene(scene, frames, record)


__all__ = ["IGNORE_LABEL", "PreloadedSource", "TrainingScene", "class_weights",
           "load_training_scenes", "preload", "sample_batch", "split_by_building"]
