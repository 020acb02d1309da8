"""metrics and figures know methods only through envelope.method.Method: no name checks,
and metrics' code names no method. Read from the syntax tree: docstrings and comments may
name a method, code may not."""

import ast
from pathlib import Path

from paths import REPO_ROOT

ROOT = REPO_ROOT
METHOD_NAMES = frozenset({"2D-S", "2D-SS", "neural3d"})
# the paper's own method names, transcribed with its figures (they coincide with ours)
PAPER_FIGURES = "metrics/report/paper_tables.py"


def _docstrings(tree: ast.AST) -> set[int]:
    return {id(n.value) for n in ast.walk(tree)
            if isinstance(n, ast.Expr) and isinstance(n.value, ast.Constant)}


def name_checks(source: str) -> list[int]:
    """Lines of ``source`` that compare something with a method's name (``==``, ``!=``,
    ``in``, ``not in``), e.g. ``s.name == "2D-SS"`` or ``"neural3d" not in names``."""
    lines = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Compare):
            operands = [node.left, *node.comparators]
            if any(isinstance(o, ast.Constant) and o.value in METHOD_NAMES for o in operands):
                lines.append(node.lineno)
    return lines


def method_mentions(source: str) -> list[tuple[int, str]]:
    """``(line, text)`` of each place the code of ``source`` names a method: a string that is
    a method's name or mentions neural3d (docstrings aside), an identifier, attribute,
    function, class or imported module with neural3d in its name."""
    tree = ast.parse(source)
    docstrings = _docstrings(tree)
    found = []
    for n in ast.walk(tree):
        if isinstance(n, ast.Constant) and isinstance(n.value, str) and id(n) not in docstrings:
            text = n.value if n.value in METHOD_NAMES or "neural3d" in n.value else None
        else:
            name = (n.id if isinstance(n, ast.Name) else n.attr if isinstance(n, ast.Attribute)
                    else n.name if isinstance(n, (ast.alias, ast.FunctionDef, ast.ClassDef))
                    else n.module or "" if isinstance(n, ast.ImportFrom) else "")
            text = name if "neural3d" in name.lower() else None
        if text is not None:
            found.append((getattr(n, "lineno", 0), text))
    return sorted(found)


def _sources(*packages: str) -> list[Path]:
    return sorted(p for package in packages for p in (ROOT / package).rglob("*.py"))


def test_no_method_is_special_cased_by_name():
    found = [f"{p.relative_to(ROOT)}:{line}" for p in _sources("metrics", "figures")
             for line in name_checks(p.read_text())]
    assert found == []


def test_metrics_code_names_no_method():
    found = [f"{p.relative_to(ROOT)}:{line} {text!r}" for p in _sources("metrics")
             if str(p.relative_to(ROOT)) != PAPER_FIGURES
             for line, text in method_mentions(p.read_text())]
    assert found == []


def test_the_checks_see_a_name_check_and_a_mention():
    assert name_checks('if any(s.name == "2D-SS" for s in specs):\n    pass\n') == [1]
    assert name_checks('specs = [s for s in specs if "neural3d" not in s.name]\n') == [1]
    assert name_checks('BUILT_IN = {"neural3d": ("neural3d.method", "METHOD")}\n') == []
    source = ('"""neural3d in a docstring is fine."""\nfrom neural3d.method import X\n'
              'budget = configs["neural3d"]\nneural3d_steps = 3\n')
    assert method_mentions(source) == [(2, "neural3d.method"), (3, "neural3d"),
                                       (4, "neural3d_steps")]
