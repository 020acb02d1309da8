"""The comparison: run what is missing, score every result against the truth, write the outputs.

:func:`compare` is what ``python -m metrics.compare`` (:mod:`metrics.compare`, the command
line and its modes) and the studies (:mod:`metrics.predicted_masks`,
:mod:`metrics.robustness`) call. Outputs (into ``out_dir``): the tables as CSV, Markdown
and LaTeX, per-building and per-facade CSVs, plots (PNG + PDF), ``provenance.json``, the
estimated footprints, the pipeline images of one facade (of the first method that writes
them) and, for each method that keeps a mesh, ``<method>_runs.json`` pointing at its
meshes: everything ``figures.make`` reads; then ``report.html``, built from the
comparison in memory (:mod:`metrics.report.html_report`).
"""

from __future__ import annotations

import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from datetime import datetime, timezone
from pathlib import Path

from envelope.atomic import write_json_atomic, write_text_atomic
from envelope.results import code_version
from envelope.scenes.scene import find_scene_folders
from envelope.truth import BuildingTruth, read_building
from metrics.export.command import FORMATS, comparison_inputs, export
from metrics.report.compare_outputs import (
    keep_pipeline_images,
    write_footprints,
    write_html_report,
    write_plots,
)
from metrics.report.report import (
    PER_BUILDING_NAME,
    PER_FACADE_NAME,
    TABLE2_NAME,
    TABLE3_NAME,
    per_building_table,
    per_facade_table,
    table2_errors,
    table3_footprint_iou,
    timing_table,
)
from metrics.report.report_data import (
    FOOTPRINTS_FOLDER,
    PIPELINE_FOLDER,
    PROVENANCE_FILE,
    report_data,
)
from metrics.report.report_estimates import ESTIMATES_NAME, estimates_table
from metrics.report.report_facades import FACADE_SCORES_NAME, facade_scores_table
from metrics.report.report_orientation import orientation_table
from metrics.report.report_paper import (
    PAPER_TABLE2_NAME,
    PAPER_TABLE3_NAME,
    paper_table2_comparison,
    paper_table3_comparison,
)
from metrics.report.report_seeds import SEED_TABLE_NAME, seed_spread_table
from metrics.report.report_visible import TABLE2_VISIBLE_NAME, table2_visible_errors
from metrics.report.tables import Table, to_csv, write_table
from metrics.run.explain import methods_provenance_text, run_timings
from metrics.run.mesh_pointers import write_mesh_pointers
from metrics.run.runner import Execute, MethodSpec, Outcome, execute_local, run_missing
from metrics.score.aggregate import GroupSummary, aggregate_by_family
from metrics.score.errors import (
    NO_TRUTH_FAMILY,
    BuildingErrors,
    FacadeErrors,
    building_errors,
    facade_errors,
    missed_facades,
)
from metrics.score.errors import failed_building as failed_row
from metrics.score.orientation_errors import (
    ORIENTATION_TABLE_NAME,
    orientation_errors_of,
    summarise_orientations,
)

PLOTS_FOLDER = "plots"
EXPORT_FOLDER = "export"  # the energy exports of a comparison with scenes without truth
CLAIMS_TABLE_NAMES = (TABLE2_VISIBLE_NAME, SEED_TABLE_NAME, PAPER_TABLE2_NAME, PAPER_TABLE3_NAME,
                      FACADE_SCORES_NAME)
TABLE_NAMES = (TABLE2_NAME, TABLE3_NAME, *CLAIMS_TABLE_NAMES, ORIENTATION_TABLE_NAME,
               ESTIMATES_NAME)
"""Every table a comparison may write; one it did not make this time leaves no file."""


@dataclass(frozen=True)
class Comparison:
    """What one comparison produced: per-building and per-facade rows and the tables.

    ``rows`` and ``facade_rows`` are the scored ones: of the scenes with truth. Where no
    scene has truth there is nothing to score: no rows, ``table2`` and ``table3`` are
    ``None``. ``estimates``: each method's figures on every scene, made where a scene lacks
    truth (:mod:`metrics.report.report_estimates`).
    """

    rows: tuple[BuildingErrors, ...]
    facade_rows: tuple[FacadeErrors, ...]
    table2: Table | None
    table3: Table | None
    outcomes: tuple[Outcome, ...]
    more_tables: tuple[Table, ...] = ()  # visible truth, seed spread, the paper's, facade scores
    orientation: Table | None = None  # WWR error per facade orientation
    estimates: Table | None = None

    @property
    def tables(self) -> tuple[Table, ...]:
        """Every table it writes as CSV, Markdown and LaTeX, in that order."""
        return tuple(t for t in (self.table2, self.table3, *self.more_tables, self.orientation,
                                 self.estimates) if t is not None)

    @property
    def printed(self) -> tuple[Table, ...]:
        """The tables the command prints: Tables 2 and 3, the claims' tables, the estimates."""
        return tuple(t for t in (self.table2, self.table3, *self.more_tables, self.estimates)
                     if t is not None)


def compare(
    data: Path,
    specs: Sequence[MethodSpec],
    results_dir: Path,
    out_dir: Path,
    *,
    allow_run: bool = True,
    reuse_stale: bool = False,
    command: str = "python -m metrics.compare",
    execute: Execute = execute_local,
) -> Comparison:
    """Run what is missing or stale (with ``execute``), evaluate every result against the
    truth and write all outputs.

    The tables (CSV, Markdown, LaTeX), per-building and per-facade CSVs are the
    same bytes on every rerun with the same code, data and settings: their
    header names the command, code version and budgets, never a time; the run
    times go to ``timing.csv`` and the moment to ``provenance.json``.

    Scenes without truth (no ``building.json``) are run like the others but not scored: the
    errors are over the scenes with truth (none: no error table at all), and the estimates
    table and the energy exports (``export/``, :mod:`metrics.export`) cover every scene.

    Raises
    ------
    ValueError
        If ``data`` holds no scene folder.
    """
    scene_dirs = find_scene_folders(data)
    outcomes = run_missing(scene_dirs, specs, results_dir, allow_run=allow_run,
                           reuse_stale=reuse_stale, execute=execute)
    truths = {d.name: _read_truth(d) for d in scene_dirs}
    without_truth = [name for name, truth in truths.items() if truth is None]
    every_row, facade_rows = evaluate(outcomes, truths)
    rows = [r for r in every_row if truths.get(r.scene) is not None]
    footer = f"made by {methods_provenance_text(specs)}; details in {PROVENANCE_FILE}"
    estimates, truth_notes = None, ()
    if without_truth:
        estimates = estimates_table(outcomes, without_truth)
        truth_notes = estimates.notes
        estimates = replace(estimates, notes=(*truth_notes, footer))
    comparison = Comparison(rows=tuple(rows), facade_rows=tuple(facade_rows), table2=None,
                            table3=None, outcomes=tuple(outcomes), estimates=estimates)
    groups = aggregate_by_family(rows)
    if rows:
        comparison = replace(comparison, **_error_tables(
            groups, facade_rows, outcomes, truths, specs, (*truth_notes, footer)))
    provenance = _provenance(data, results_dir, specs, outcomes, command)
    if without_truth:
        provenance["scenes_without_truth"] = without_truth
    _write_tables(comparison, out_dir, f"produced by `{command}`; {footer}")
    write_plots(groups, rows, out_dir / PLOTS_FOLDER)
    write_footprints(outcomes, out_dir / FOOTPRINTS_FOLDER)
    if without_truth:
        export(comparison_inputs({n: t for n, t in truths.items() if t is not None},
                                 [o.result for o in outcomes if o.result is not None]),
               out_dir / EXPORT_FOLDER, FORMATS,
               produced_by=f"{command}; {'; '.join(truth_notes)}")
    for spec in specs:
        write_mesh_pointers(scene_dirs, spec, out_dir)
    with_images = [s for s in specs if s.debug_images is not None and s.protocols]
    if allow_run and with_images:
        keep_pipeline_images(scene_dirs, with_images[0], out_dir / PIPELINE_FOLDER)
    write_json_atomic(out_dir / PROVENANCE_FILE, provenance)
    write_html_report(report_data(comparison.tables, every_row, provenance, out_dir))
    return comparison


def _error_tables(groups: Sequence[GroupSummary], facade_rows: Sequence[FacadeErrors],
                  outcomes: Sequence[Outcome], truths: Mapping[str, BuildingTruth | None],
                  specs: Sequence[MethodSpec], notes: tuple[str, ...]) -> dict[str, object]:
    """Tables 2 and 3, the claims' tables and the orientation errors of the scored rows,
    each ending with ``notes``."""
    footprint_methods = {s.name for s in specs if s.has_footprint}
    table2, table3 = table2_errors(groups), table3_footprint_iou(groups, footprint_methods)
    orientation = orientation_table(summarise_orientations(orientation_errors_of(
        (o.result, truths.get(o.scene)) for o in outcomes if o.result is not None)))
    return {
        "table2": replace(table2, notes=(*table2.notes, *notes)),
        "table3": replace(table3, notes=(*table3.notes, *notes)),
        "more_tables": (*claims_tables(groups, paper_names_of(specs)),
                        *((facade_scores_table(facade_rows, groups),) if facade_rows else ())),
        "orientation": replace(orientation, notes=(*orientation.notes, *notes)),
    }


def _write_tables(comparison: Comparison, out_dir: Path, comment: str) -> None:
    """The tables (CSV, Markdown, LaTeX; none left of a table not made this time) and the
    per-building, per-facade (where something was scored) and timing CSVs, each headed by
    ``comment``."""
    out_dir.mkdir(parents=True, exist_ok=True)
    for table in comparison.tables:
        write_table(table, out_dir, comment)
    for name in set(TABLE_NAMES) - {t.name for t in comparison.tables}:
        for suffix in (".csv", ".md", ".tex"):
            (out_dir / f"{name}{suffix}").unlink(missing_ok=True)
    scored = ((per_building_table(comparison.rows), per_facade_table(comparison.facade_rows))
              if comparison.table2 is not None else ())
    for name in () if scored else (PER_BUILDING_NAME, PER_FACADE_NAME):
        (out_dir / f"{name}.csv").unlink(missing_ok=True)
    for table in (*scored, timing_table(run_timings(comparison.outcomes))):
        write_text_atomic(out_dir / f"{table.name}.csv", to_csv(table, comment))


def paper_names_of(specs: Sequence[MethodSpec]) -> dict[str, str]:
    """Each method's name -> its name in the BuildNet3D paper, for those the paper has."""
    return {s.name: s.paper_name for s in specs if s.paper_name is not None}


def claims_tables(groups: Sequence[GroupSummary],
                  paper_names: Mapping[str, str]) -> tuple[Table, ...]:
    """Table 2 against the full and the visible facade truth, the seed-to-seed spread (when
    a method ran with several seeds) and ours beside the BuildNet3D paper's Tables 2 and 3
    (each only when it has a row)."""
    tables = (table2_visible_errors(groups), seed_spread_table(groups),
              paper_table2_comparison(groups, paper_names),
              paper_table3_comparison(groups, paper_names))
    return tuple(t for t in tables if t is not None and t.rows)


def evaluate(
    outcomes: Sequence[Outcome], truths: dict[str, BuildingTruth | None]
) -> tuple[list[BuildingErrors], list[FacadeErrors]]:
    """Per-building and per-facade rows of every outcome (failed outcomes as failed rows)."""
    rows: list[BuildingErrors] = []
    facade_rows: list[FacadeErrors] = []
    for o in outcomes:
        truth = truths.get(o.scene)
        family = truth.type if truth is not None else NO_TRUTH_FAMILY
        if o.result is None:
            rows.append(failed_row(o.scene, family, o.method, o.protocol, o.reason))
            facade_rows.extend(missed_facades(o.scene, o.method, o.protocol, truth, o.reason))
            continue
        rows.append(building_errors(o.result, truth, stale=o.status == "stale"))
        facade_rows.extend(facade_errors(o.result, truth))
    return rows, facade_rows


def _read_truth(scene_dir: Path) -> BuildingTruth | None:
    path = scene_dir / "building.json"
    if not path.is_file():
        return None
    try:
        return read_building(path)
    except ValueError as exc:
        print(f"warning: {exc}; {scene_dir.name} is compared without ground truth",
              file=sys.stderr)
        return None


def _provenance(
    data: Path, results_dir: Path, specs: Sequence[MethodSpec], outcomes: Sequence[Outcome],
    command: str,
) -> dict:
    return {
        "produced_by": command,
        "code_version": code_version(),
        "created_utc": datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "data": str(data.resolve()),
        "results": str(results_dir.resolve()),
        "methods": {s.name: {"protocols": list(s.protocols), "config": s.config} for s in specs},
        "runs": [
            {
                "scene": o.scene, "method": o.method, "protocol": o.protocol,
                "status": o.status, "reason": o.reason,
                "result_file": str(o.path) if o.path else None,
                "result_code_version": o.result.code_version if o.result else None,
                "steps": o.result.steps if o.result else None,
                "cut_short": o.result.cut_short if o.result else None,
                "wall_time_s": o.result.wall_time_s if o.result else None,
                "provenance": (o.result.provenance.to_json_dict()
                               if o.result and o.result.provenance else None),
            }
            for o in outcomes
        ],
    }
