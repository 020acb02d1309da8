"""Scenes copied with a segmenter's masks, and the method specs that run on them
(``python -m metrics.compare --masks predicted[:MODEL]``; the study that compares them with
the exact masks is :mod:`metrics.predicted_masks`).

Every scene is copied once into ``<data>-masks/<key>/<scene>`` with the semantic image
of each view the methods read replaced by the segmenter's prediction from its RGB
(:func:`segment.scene_masks.predicted_scene`: cached by provenance, the truth and
every other file hard links to the original; views no method reads are left out, see
:func:`splits_read`). The methods run on the copies unchanged; their results go to
``<results>/masks/<key>`` and carry the segmenter in their config under ``masks``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

from tqdm import tqdm

from envelope.protocols import EVAL_SPLIT, TRAIN_PROTOCOL
from envelope.scenes.scene import find_scene_folders
from metrics.run.runner import MethodSpec
from segment.scene_masks import predicted_scene
from segment.segmenter import Segmenter, resolve_segmenter

CONFIG_KEY = "masks"
PREDICTED = "predicted"
TABLE_NAME = "exact_vs_predicted"


@dataclass(frozen=True)
class MasksRequest:
    """``--masks predicted[:MODEL]``: the segmenter (``model``: ``None`` for the committed
    weights, a weights file ``*.pt`` or an installed plugin's name) and its torch threads."""

    model: str | None = None
    threads: int = 2

    def __post_init__(self) -> None:
        if self.threads < 1:
            raise ValueError(f"--masks-threads must be >= 1, got {self.threads}")


def parse_masks(text: str, threads: int = 2) -> MasksRequest:
    """``"predicted"`` -> the default segmenter, ``"predicted:MODEL"`` -> MODEL.

    Raises
    ------
    ValueError
        For anything else, or ``threads`` < 1.
    """
    kind, sep, model = text.partition(":")
    if kind.strip() != PREDICTED or (sep and not model.strip()):
        raise ValueError(f"--masks {text!r}: write 'predicted' or 'predicted:MODEL' (MODEL: a "
                         f"weights file *.pt or an installed segmenter plugin's name)")
    return MasksRequest(model.strip() or None, threads)


def masks_segmenter(request: MasksRequest) -> Segmenter:
    """The segmenter ``request`` names, loaded (refused weights or plugins raise
    ``ValueError`` here, before anything runs)."""
    return resolve_segmenter(request.model, threads=request.threads)


def masks_key(segmenter: Segmenter) -> str:
    """A folder name for a segmenter's masks: ``predicted-<name>-<weights>`` (``<name>``: the
    segmenter's name, a weights file's stem) or ``predicted-<plugin name>`` (file-system
    safe)."""
    label = Path(segmenter.name).stem
    safe = "".join(c if c.isalnum() or c in "-_." else "_" for c in label)
    weights = segmenter.identity.get("weights")
    return f"{PREDICTED}-{safe}" + (f"-{weights[:8]}" if weights else "")


@dataclass(frozen=True)
class PredictedRun:
    """Where a comparison on ``segmenter``'s masks reads scenes and writes results and
    outputs."""

    data: Path
    results: Path
    out: Path
    segmenter: Segmenter


def splits_read(specs: Sequence[MethodSpec]) -> tuple[str, ...]:
    """The frame splits the methods read: their protocols (``ideal``, ``multi``: the
    facade views of the 2D methods; ``train``: the orbit views, every built-in method's),
    and the held-out ``eval`` orbit views when a trained method (one that keeps a run folder,
    ``artefacts_dir``: neural3d) runs on ``train``: it renders them for its own checks. Only
    these are segmented: the 2D methods read 828 of the ``paper`` preset's 6428 frames on
    ``ideal`` and ``multi``, and the orbit's ``train`` frames besides."""
    splits = {p for s in specs for p in s.protocols}
    if any(TRAIN_PROTOCOL in s.protocols and s.artefacts_dir is not None for s in specs):
        splits.add(EVAL_SPLIT)
    return tuple(sorted(splits))


def predicted_run(data: Path, results: Path, out: Path, segmenter: Segmenter,
                  splits: Sequence[str] | None = None) -> PredictedRun:
    """Make (or reuse) the mask copy of every scene of ``data`` (of the frames of
    ``splits``; ``None``: every frame) and name the folders.

    Raises
    ------
    ValueError
        A scene the segmenter cannot take (see :func:`segment.scene_masks.predicted_scene`).
    """
    key = masks_key(segmenter)
    cache = data.with_name(f"{data.name}-masks") / key
    scenes = find_scene_folders(data, with_images=True)
    for scene_dir in tqdm(scenes, desc=f"masks {key}", unit="scene", leave=False):
        predicted_scene(scene_dir, cache, segmenter, splits=splits)
    return PredictedRun(cache, results / "masks" / key, out.with_name(f"{out.name}-masks-{key}"),
                        segmenter)


def with_predicted_masks(specs: Sequence[MethodSpec], segmenter: Segmenter) -> list[MethodSpec]:
    """The same methods, the configs their results record naming the segmenter."""
    record = {"segmenter": segmenter.name, **segmenter.identity}
    return [replace(s, conditions={**s.conditions, CONFIG_KEY: record}) for s in specs]
