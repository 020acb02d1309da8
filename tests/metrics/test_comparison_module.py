"""The comparison sits below its command line and its studies: ``metrics.comparison`` is
imported by ``metrics.compare`` (the CLI), ``metrics.predicted_masks`` and
``metrics.robustness``, which call it directly (no ``compare`` passed in as a callback)."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

import metrics
from metrics.predicted_masks import compare_on_predicted_masks
from metrics.robustness import run_study

METRICS = Path(metrics.__file__).parent


def _imported_modules(path: Path) -> set[str]:
    tree = ast.parse(path.read_text())
    return {node.module for node in ast.walk(tree)
            if isinstance(node, ast.ImportFrom) and node.module} | {
        alias.name for node in ast.walk(tree) if isinstance(node, ast.Import)
        for alias in node.names}


def test_the_studies_import_the_comparison_not_the_command_line():
    for study in ("predicted_masks.py", "robustness.py", "compare.py"):
        imported = _imported_modules(METRICS / study)
        assert "metrics.comparison" in imported, study
        assert "metrics.compare" not in imported, study
    below = _imported_modules(METRICS / "comparison.py")
    assert not below & {"metrics.compare", "metrics.predicted_masks", "metrics.robustness"}


def test_no_study_takes_the_comparison_as_an_argument():
    for study in (compare_on_predicted_masks, run_study):
        params = inspect.signature(study).parameters
        assert "compare" not in params and all(
            "Callable[..., " not in str(p.annotation) for p in params.values()), study
    import metrics.run.predicted_masks as run_masks

    assert not hasattr(run_masks, "CompareFn")
