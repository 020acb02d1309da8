"""Comparisons on a segmenter's masks (``python -m metrics.compare --masks predicted[:MODEL]``).

The comparison on the exact masks runs (reusing its stored results), then the same on the
scene copies with the segmenter's masks (:mod:`metrics.run.predicted_masks`); the truth stays
the exact one. ``<out>-masks-<key>`` gets, beside the usual outputs, ``exact_vs_predicted``
(CSV, Markdown, LaTeX): per building, the segmenter's window IoU and each method's WWR,
window and facade error on exact and on predicted masks, and per family the means, over the
scenes with truth (scenes without have estimates only, in each comparison's estimates table).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from envelope.classes import SemanticClass
from envelope.scenes.scene import find_scene_folders, read_scene
from metrics.comparison import compare
from metrics.report.tables import Table, write_table
from metrics.run.predicted_masks import (
    TABLE_NAME,
    PredictedRun,
    predicted_run,
    splits_read,
    with_predicted_masks,
)
from metrics.run.runner import MethodSpec
from metrics.score.aggregate import summarise
from metrics.score.errors import BuildingErrors
from segment.evaluate import SceneIou, masks_scene_iou
from segment.segmenter import Segmenter


def compare_on_predicted_masks(
    segmenter: Segmenter, data: Path, results: Path, out: Path,
    specs_for: Callable[[Path], list[MethodSpec]], *, command: str, **options,
) -> tuple[tuple[Table, ...], PredictedRun]:
    """Compare on exact masks and on ``segmenter``'s; write the table :data:`TABLE_NAME`
    into the predicted run's ``out`` and return the tables to print with the run's folders
    (``options`` go to :func:`metrics.comparison.compare`; ``specs_for(results folder)``
    makes the methods' specs).

    The table scores the scenes with truth; where none has truth it is not written (nor
    printed), and the predicted-mask comparison's estimates table is what there is to print
    (:mod:`metrics.report.report_estimates`)."""
    specs = specs_for(results)
    exact = compare(data, specs, results, out, command=command, **options)
    run = predicted_run(data, results, out, segmenter, splits_read(specs))
    predicted = compare(run.data, with_predicted_masks(specs_for(run.results), segmenter),
                        run.results, run.out, command=command, **options)
    exact_dirs = {d.name: d for d in find_scene_folders(data)}
    scored = {r.scene for r in exact.rows}
    ious = [masks_scene_iou(read_scene(exact_dirs[d.name]), read_scene(d))
            for d in find_scene_folders(run.data) if d.name in scored]
    table = exact_vs_predicted_table(exact.rows, predicted.rows, ious, segmenter.name)
    if table.rows:
        write_table(table, run.out, f"produced by `{command}`")
    else:
        for suffix in (".csv", ".md", ".tex"):
            (run.out / f"{TABLE_NAME}{suffix}").unlink(missing_ok=True)
    tables = ((table,) if table.rows else ()) + (
        (predicted.estimates,) if predicted.estimates is not None else ())
    return tables, run


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
