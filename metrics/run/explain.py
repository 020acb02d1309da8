"""Where a comparison's figures came from, in words: table footers, run timings, ``--explain``.

Every text here is made from the methods' specs and the results' provenance
records (:mod:`envelope.provenance`), never from the clock, so tables that carry
it stay byte-identical between reruns.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from envelope.provenance import code_version, provenance_changes
from envelope.results import read_result, result_filename
from metrics.run.runner import MethodSpec, Outcome, expected_provenance
from metrics.score.errors import RunTiming


def methods_provenance_text(specs: Sequence[MethodSpec]) -> str:
    """One line naming, per method, its budget (if any), code fingerprints and config digest.

    E.g. ``"2D-SS: code dataset@1a2b.. baselines@3c4d.., config 5e6f..; NAME: fast
    preset, 1000 steps (cap 60 min), cpu, 2 threads, code ..."`` (the budget, for a
    method whose config record has one: :func:`recorded_steps`).
    """
    parts = []
    for spec in specs:
        record = expected_provenance(Path("."), spec)
        code = " ".join(f"{m}@{fp}" for m, fp in record.code.items())
        budget = spec.config.get("budget")
        said = ""
        if recorded_steps(spec.config) is not None:
            said = (f"{budget.get('preset')} preset, {budget['steps']} steps "
                    f"(cap {budget.get('max_seconds', 0) / 60:g} min), "
                    f"{budget.get('device')}, {budget.get('threads')} threads, ")
        parts.append(f"{spec.name}: {said}code {code}, config {_config_digest(spec)}")
    return f"envelope-bench {code_version()}; " + "; ".join(parts)


def recorded_steps(config: Mapping[str, Any]) -> int | None:
    """The training steps per building that a method's config record names as its budget
    (``config["budget"]["steps"]``), or ``None`` for a method that does not train."""
    budget = config.get("budget")
    return budget["steps"] if isinstance(budget, dict) and "steps" in budget else None


def run_timings(outcomes: Sequence[Outcome]) -> list[RunTiming]:
    """Wall time of each outcome's result (``None`` for a failed run)."""
    return [
        RunTiming(o.scene, o.method, o.protocol, o.status,
                  o.result.steps if o.result else None,
                  o.result.wall_time_s if o.result else None)
        for o in outcomes
    ]


def explain(scene_dir: Path, spec: MethodSpec, results_dir: Path) -> str:
    """A result's full provenance record for each of ``spec``'s protocols on ``scene_dir``,
    and whether the current code would reuse it (or what changed).
    """
    lines = []
    expected = expected_provenance(scene_dir, spec)
    for protocol in spec.protocols:
        path = results_dir / result_filename(scene_dir.name, spec.name, protocol)
        lines.append(f"# {scene_dir.name} / {spec.name} / {protocol}: {path}")
        if not path.is_file():
            lines.append("no result file: run `python -m metrics.compare` to make it")
            continue
        try:
            result = read_result(path)
        except ValueError as exc:
            lines.append(f"unreadable: {exc}")
            continue
        changes = provenance_changes(result.provenance, expected)
        lines.append("up to date: reused by the current code" if not changes else
                     "stale (recomputed unless --reuse-stale): "
                     + "; ".join(str(c) for c in changes))
        lines.append(f"steps: {result.steps}; cut short: {result.cut_short}; "
                     f"wall time: {result.wall_time_s:.1f} s; "
                     f"code version: {result.code_version or 'unknown'}")
        record = result.provenance.to_json_dict() if result.provenance else None
        lines.append(json.dumps({"provenance": record, "config": result.config}, indent=2,
                                sort_keys=True))
    return "\n".join(lines)


def _config_digest(spec: MethodSpec) -> str:
    text = json.dumps(spec.config, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:12]
