"""Data flows one way: dataset -> baselines / neural3d -> metrics -> figures, never back.

Read from the source files' import statements (``import x`` and ``from x import y``,
at any depth, including the ones inside functions), not by importing anything.
"""

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
# A package may import the packages of a lower layer and its own, nothing later in the flow.
LAYER = {"dataset": 0, "baselines": 1, "neural3d": 1, "metrics": 2, "figures": 3}


def project_imports(path: Path) -> set[str]:
    """Top-level project packages a Python file imports."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names = [node.module]
        else:
            continue
        found |= {n.split(".")[0] for n in names if n.split(".")[0] in LAYER}
    return found


@pytest.mark.parametrize("package", sorted(LAYER))
def test_no_package_imports_one_later_in_the_flow(package):
    wrong = []
    for path in sorted((ROOT / package).rglob("*.py")):
        for other in project_imports(path):
            sideways = LAYER[other] == LAYER[package] and other != package
            if LAYER[other] > LAYER[package] or sideways:
                wrong.append(f"{path.relative_to(ROOT)} imports {other}")
    assert wrong == []


def test_the_check_sees_imports_inside_functions(tmp_path):
    source = tmp_path / "m.py"
    source.write_text("def f():\n    from metrics.errors import x\n    import figures.make\n")
    assert project_imports(source) == {"metrics", "figures"}
