"""The robustness study (``python -m metrics.compare --robustness``): error against severity.

For each degradation and severity of a :class:`RobustnessStudy` the comparison
runs on degraded inputs (:mod:`metrics.run.degraded`); severity 0 is the clean
comparison. The study writes ``robustness.csv`` / ``.md`` (mean WWR, window
and facade APE per method, views, degradation and severity, pooled over
buildings) and ``robustness.png`` / ``.pdf`` (one panel per degradation, one
curve per method and views) into its output folder.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from dataset.degrade.spec import DegradeSpec
from envelope.atomic import write_text_atomic
from metrics.comparison import compare
from metrics.report.robustness_plot import RobustnessRow, plot_robustness
from metrics.report.tables import Table, to_csv, to_markdown
from metrics.run.degraded import degraded_run, with_degradation
from metrics.run.runner import Execute, MethodSpec, execute_local
from metrics.score.aggregate import method_rank, protocol_rank
from metrics.score.errors import BuildingErrors

SpecsFor = Callable[[Path], list[MethodSpec]]
"""results folder -> the method specs to run there."""


@dataclass(frozen=True)
class RobustnessStudy:
    """Degradations and severities of the study (a laptop's worth on the tiny benchmark).

    ``heavy_levels``: ``"all"`` runs the heavy methods (``Method.heavy``, a trained one) at
    every severity, ``"max"`` only at the highest of each degradation (the default; the
    2D methods always run at all).
    """

    levels: tuple[tuple[str, tuple[float, ...]], ...] = (
        ("mask_noise", (0.5, 1.0, 2.0)),
        ("occluders", (1.0, 2.0, 4.0)),
        ("pose", (0.1, 0.3, 1.0)),
        ("depth_noise", (0.25, 0.5, 1.0)),
    )
    seed: int = 0
    heavy_levels: str = "max"

    def __post_init__(self) -> None:
        if self.heavy_levels not in ("all", "max"):
            raise ValueError(f"heavy_levels must be 'all' or 'max', got "
                             f"{self.heavy_levels!r}")
        for name, severities in self.levels:
            for s in severities:
                DegradeSpec(name, s, self.seed)  # type: ignore[arg-type]

    @property
    def heavy_comparisons(self) -> int:
        """How many comparisons run the heavy methods: the clean one and each degraded one."""
        if self.heavy_levels == "max":
            return 1 + len(self.levels)
        return 1 + sum(len(severities) for _, severities in self.levels)


def run_study(
    data: Path, results: Path, out: Path, specs_for: SpecsFor, study: RobustnessStudy,
    *, execute: Execute = execute_local,
) -> list[RobustnessRow]:
    """Run the clean comparison and every (degradation, severity) with
    :func:`metrics.comparison.compare`, their missing runs made with ``execute``; write
    table and plot."""
    clean = compare(data, specs_for(results), results, out / "clean",
                    command="python -m metrics.compare --robustness", execute=execute)
    rows: list[RobustnessRow] = []
    for name, _ in study.levels:
        rows += summarise(clean.rows, name, 0.0)
    for name, severities in study.levels:
        for severity in severities:
            degradation = (DegradeSpec(name, severity, study.seed),)  # type: ignore[arg-type]
            run = degraded_run(data, results, out / "runs", degradation)
            specs = specs_for(run.results)
            if study.heavy_levels == "max" and severity < max(severities):
                specs = [s for s in specs if not s.heavy]
            comparison = compare(run.data, with_degradation(specs, degradation), run.results,
                                 run.out, command=f"python -m metrics.compare --robustness "
                                 f"({degradation[0].text})", execute=execute)
            rows += summarise(comparison.rows, name, severity)
    table = robustness_table(rows)
    comment = "robustness study: mean APE (%) over buildings; severity 0 = clean inputs"
    write_text_atomic(out / "robustness.csv", to_csv(table, comment))
    write_text_atomic(out / "robustness.md", to_markdown(table, comment))
    plot_robustness(rows, out / "robustness")
    return rows


def summarise(rows: Sequence[BuildingErrors], degradation: str,
              severity: float) -> list[RobustnessRow]:
    """Pool per-building rows into one :class:`RobustnessRow` per (method, views)."""
    out = []
    keys = sorted({(r.method, r.protocol) for r in rows},
                  key=lambda k: (method_rank(k[0]), protocol_rank(k[1])))
    for method, protocol in keys:
        mine = [r for r in rows if r.method == method and r.protocol == protocol]
        out.append(RobustnessRow(
            degradation, severity, method, protocol, len(mine),
            sum(r.status == "failed" for r in mine),
            _mean([r.wwr_ape for r in mine]), _mean([r.window_ape for r in mine]),
            _mean([r.facade_ape for r in mine]),
        ))
    return out


def robustness_table(rows: Sequence[RobustnessRow]) -> Table:
    """One line per (degradation, severity, method, views)."""
    return Table(
        name="robustness",
        title="Robustness: mean APE (%) against input-degradation severity",
        columns=("degradation", "severity", "method", "views", "buildings", "failed",
                 "WWR APE (%)", "window APE (%)", "facade APE (%)"),
        keys=("degradation", "severity", "method", "protocol", "buildings", "failed",
              "wwr_ape", "window_ape", "facade_ape"),
        rows=tuple((r.degradation, f"{r.severity:g}", r.method, r.protocol, r.buildings,
                    r.failed, r.wwr_ape, r.window_ape, r.facade_ape) for r in rows),
        decimals=1,
    )


def _mean(values: Sequence[float | None]) -> float | None:
    vals = [v for v in values if v is not None and math.isfinite(v)]
    return sum(vals) / len(vals) if vals else None
