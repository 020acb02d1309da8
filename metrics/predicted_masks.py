"""Comparisons on a segmenter's masks (``python -m metrics.compare --masks predicted[:MODEL]``).

Every scene is copied once into ``<data>-masks/<key>/<scene>`` with the semantic image
of each view the methods read replaced by the segmenter's prediction from its RGB
(:func:`segment.scene_masks.predicted_scene`: cached by provenance, the truth and
every other file hard links to the original; views no method reads are left out, see
:func:`splits_read`). The methods run on the copies
unchanged; their results go to ``<results>/masks/<key>`` and carry the segmenter in
their config under ``masks``; the truth stays the exact one. The usual comparison on
the exact masks runs too (reusing its stored results), and ``<out>-masks-<key>``
gets, beside the usual outputs, ``exact_vs_predicted`` (CSV, Markdown, LaTeX): per
building, the segmenter's window IoU and each method's WWR, window and facade error
on exact and on predicted masks, and per family the means.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

from dataset.core.classes import SemanticClass
from dataset.core.protocols import EVAL_SPLIT, TRAIN_PROTOCOL
from dataset.scenes.scene import read_scene
from metrics.aggregate import summarise
from metrics.errors import BuildingErrors
from metrics.runner import MethodSpec, find_scenes
from metrics.tables import Table, write_table
from segment.evaluate import SceneIou, masks_scene_iou
from segment.scene_masks import predicted_scene
from segment.segmenter import DEFAULT_NAME, Segmenter, resolve_segmenter

CONFIG_KEY = "masks"
PREDICTED = "predicted"
TABLE_NAME = "exact_vs_predicted"
CompareFn = Callable[..., Any]
"""``metrics.compare.compare``: ``(data, specs, results, out, **options) -> Comparison``
(passed in: ``metrics.compare`` imports this module, not the other way round)."""


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
    """A folder name for a segmenter's masks: ``predicted-default-<weights>`` or
    ``predicted-<plugin name>`` (file-system safe)."""
    label = DEFAULT_NAME if segmenter.name == DEFAULT_NAME else Path(segmenter.name).stem
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
    facade views of the 2D methods; ``train``: the orbit views), and with ``train`` the
    held-out ``eval`` orbit views a trained method renders for its own checks. Only these
    are segmented: the 2D methods read 828 of the ``paper`` preset's 6428 frames."""
    splits = {p for s in specs for p in s.protocols}
    if TRAIN_PROTOCOL in splits:
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
    scenes = [d for d in find_scenes(data) if (d / "transforms.json").is_file()]
    for scene_dir in tqdm(scenes, desc=f"masks {key}", unit="scene", leave=False):
        predicted_scene(scene_dir, cache, segmenter, splits=splits)
    return PredictedRun(cache, results / "masks" / key, out.with_name(f"{out.name}-masks-{key}"),
                        segmenter)


def with_predicted_masks(specs: Sequence[MethodSpec], segmenter: Segmenter) -> list[MethodSpec]:
    """The same methods, their requested and written configs naming the segmenter (each
    run stays picklable, so a method still runs in a process of its own or on Ray)."""
    record = {"segmenter": segmenter.name, **segmenter.identity}
    return [replace(s, config={**s.config, CONFIG_KEY: record},
                    run=partial(_run_on_masks, s.run, record)) for s in specs]


def _run_on_masks(run: Callable, record: dict[str, Any], scene_dir: Path, protocol: str, **kwargs):
    """``run``'s result with the segmenter ``record`` in its config."""
    result = run(scene_dir, protocol, **kwargs)
    return replace(result, config={**result.config, CONFIG_KEY: record})


def compare_on_predicted_masks(
    segmenter: Segmenter, data: Path, results: Path, out: Path,
    specs_for: Callable[[Path], list[MethodSpec]], compare: CompareFn, *, command: str,
    **options,
) -> tuple[Table, PredictedRun]:
    """Compare on exact masks and on ``segmenter``'s; write the table :data:`TABLE_NAME`
    into the predicted run's ``out`` and return it with the run's folders (``options``
    go to ``compare``; ``specs_for(results folder)`` makes the methods' specs)."""
    specs = specs_for(results)
    exact = compare(data, specs, results, out, command=command, **options)
    run = predicted_run(data, results, out, segmenter, splits_read(specs))
    predicted = compare(run.data, with_predicted_masks(specs_for(run.results), segmenter),
                        run.results, run.out, command=command, **options)
    exact_dirs = {d.name: d for d in find_scenes(data)}
    ious = [masks_scene_iou(read_scene(exact_dirs[d.name]), read_scene(d))
            for d in find_scenes(run.data) if d.name in exact_dirs]
    table = exact_vs_predicted_table(exact.rows, predicted.rows, ious, segmenter.name)
    write_table(table, run.out, f"produced by `{command}`")
    return table, run


def exact_vs_predicted_table(exact: Sequence[BuildingErrors], predicted: Sequence[BuildingErrors],
                             ious: Sequence[SceneIou], segmenter: str) -> Table:
    """Per (building, method, views): the segmenter's window IoU and the WWR, window and
    facade APE (%) on exact and on predicted masks; then per (family, method, views) the
    means over the buildings."""
    window_iou = {s.scene: s.window_iou for s in ious}
    by_key = {(r.scene, r.method, r.protocol): r for r in exact}
    rows = []
    for p in predicted:
        e = by_key.get((p.scene, p.method, p.protocol))
        rows.append((p.scene, p.family, _finite(window_iou.get(p.scene)), p.method, p.protocol,
                     *_pairs(e, p)))
    for family in sorted({r[1] for r in rows}):
        for method, protocol in dict.fromkeys((r[3], r[4]) for r in rows if r[1] == family):
            group = [r for r in rows if r[1:2] == (family,) and r[3:5] == (method, protocol)]
            means = [summarise(r[k] for r in group).mean for k in range(5, 11)]
            iou = summarise(r[2] for r in group).mean
            rows.append((f"mean ({len(group)})", family, iou, method, protocol, *means))
    return Table(
        name=TABLE_NAME,
        title=f"Exact masks vs predicted masks ({segmenter}): segmenter window IoU and "
              "absolute percentage errors (%)",
        columns=("Building", "Family", "Window IoU", "Method", "Views", "WWR exact",
                 "WWR predicted", "Window exact", "Window predicted", "Facade exact",
                 "Facade predicted"),
        keys=("scene", "family", "window_iou", "method", "protocol", "wwr_ape_exact",
              "wwr_ape_predicted", "window_ape_exact", "window_ape_predicted",
              "facade_ape_exact", "facade_ape_predicted"),
        rows=tuple(rows),
        notes=(f"window IoU of the {segmenter} segmenter against the exact masks, pooled over "
               f"the views of each building that the methods read (class "
               f"{int(SemanticClass.WINDOW)}, window)",),
    )


def _pairs(exact: BuildingErrors | None, predicted: BuildingErrors) -> list[float | None]:
    out: list[float | None] = []
    for name in ("wwr_ape", "window_ape", "facade_ape"):
        out += [getattr(exact, name) if exact is not None else None, getattr(predicted, name)]
    return out


def _finite(value: float | None) -> float | None:
    return None if value is None or not np.isfinite(value) else float(value)
