"""Data flows one way: envelope (the contracts) -> dataset -> baselines / neural3d / segment ->
metrics -> figures, never back.

Read from the source files' import statements (``import x`` and ``from x import y``,
at any depth, including the ones inside functions), not by importing anything.
"""

import ast
from pathlib import Path

import pytest
from paths import REPO_ROOT

ROOT = REPO_ROOT
# A package may import the packages of a lower layer and its own, nothing later in the flow.
LAYER = {"envelope": 0, "dataset": 1, "baselines": 2, "neural3d": 2, "segment": 2, "metrics": 3,
         "figures": 4}


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
    source.write_text("def f():\n    from metrics.score.errors import x\n    import figures.make\n")
    assert project_imports(source) == {"metrics", "figures"}


# Inside a package, its sub-packages follow the same rule (the package's own modules are its
# top: its commands; in ``envelope`` they are its bottom: the contracts). ``neural3d.config`` is
# the configs every part reads.
SUBLAYER = {
    "envelope": {"executors": 1, "geometry": 1, "scenes": 2},
    "dataset": {"families": 1, "rendering": 1, "scenes": 2, "importers": 3, "degrade": 3,
                "examples": 3},
    "neural3d": {"config": 0, "field": 1, "rendering": 2, "training": 3, "extraction": 3},
    "metrics": {"score": 0, "run": 1, "report": 2, "export": 3},
}
TOP = 9
BOTTOM_MODULES = {"envelope"}  # packages whose own modules are the base of their sub-packages


def module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imported_modules(path: Path) -> set[str]:
    """Project modules a Python file imports (``from a.b import c`` counts ``a.b`` and, when
    it is a module, ``a.b.c``)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            found.add(node.module)
            found |= {f"{node.module}.{alias.name}" for alias in node.names}
    return {m for m in found if m.split(".")[0] in LAYER and _exists(m)}


def _exists(module: str) -> bool:
    base = ROOT.joinpath(*module.split("."))
    return base.with_suffix(".py").is_file() or (base / "__init__.py").is_file()


def sublayer(module: str) -> tuple[str, int]:
    """(package, rank) of a module inside its package."""
    parts = module.split(".")
    ranks = SUBLAYER.get(parts[0], {})
    own = 0 if parts[0] in BOTTOM_MODULES else TOP
    if len(parts) < 2:
        return parts[0], own
    return parts[0], ranks.get(parts[1], own)


def group(module: str) -> tuple[str, ...]:
    """A module's sub-package, or its package alone for the package's own modules."""
    parts = tuple(module.split("."))
    return parts[:2] if len(parts) > 1 and parts[1] in SUBLAYER.get(parts[0], {}) else parts[:1]


@pytest.mark.parametrize("package", sorted(SUBLAYER))
def test_no_sub_package_imports_one_later_in_its_flow(package):
    wrong = []
    for path in sorted((ROOT / package).rglob("*.py")):
        mine = module_name(path)
        _, rank = sublayer(mine)
        for other in imported_modules(path):
            other_package, other_rank = sublayer(other)
            same_group = group(other) == group(mine)
            if other_package == package and not same_group and other_rank >= rank < TOP:
                wrong.append(f"{path.relative_to(ROOT)} imports {other}")
    assert wrong == []


@pytest.mark.slow
def test_no_module_imports_itself_in_a_circle():
    graph = {module_name(p): imported_modules(p) for package in LAYER
             for p in (ROOT / package).rglob("*.py")}
    cycles, done = [], set()

    def visit(module: str, stack: list[str]) -> None:
        if module in stack:
            cycles.append(" -> ".join([*stack[stack.index(module):], module]))
            return
        if module in done:
            return
        for other in sorted(graph.get(module, ())):
            if not module.startswith(other + ".") and other != module:  # a package's own parts
                visit(other, [*stack, module])
        done.add(module)

    for module in sorted(graph):
        visit(module, [])
    assert cycles == [], cycles
