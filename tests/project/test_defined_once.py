"""Each name and default is defined in one place: the sources' syntax trees show it.

Protocol and split names, the class palette, the merge decimals, the field's chunk size, the
marching-cubes resolution, a scene's name, face normals and in-plane bases each have one
definition; everything else imports it. Read from the sources, not by importing.
"""

import ast
from functools import cache
from pathlib import Path

import pytest
from paths import REPO_ROOT

ROOT = REPO_ROOT
PACKAGES = ("envelope", "dataset", "baselines", "neural3d", "segment", "metrics", "figures")
# Importers that issue 17 works on at the same time as this check was written; their frame
# splits are converted to envelope.protocols' names when both branches meet.


def sources() -> list[Path]:
    return sorted(p for package in PACKAGES for p in (ROOT / package).rglob("*.py"))


def code_strings(path: Path) -> list[tuple[int, str]]:
    """String literals of ``path`` that are values in code: not docstrings, comments or dict
    keys (a config record's ``"train"`` entry is a key, not the protocol)."""
    tree = ast.parse(path.read_text())
    skip = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant):
            skip.add(id(node.value))  # docstrings and bare strings
        if isinstance(node, ast.Dict):
            skip |= {id(k) for k in node.keys if k is not None}
    return [(n.lineno, n.value) for n in ast.walk(tree)
            if isinstance(n, ast.Constant) and isinstance(n.value, str) and id(n) not in skip]


def _module_names(tree: ast.Module) -> list[tuple[int, str]]:
    """``(line, name)`` of each name a module assigns or defines at its top level."""
    found = []
    for node in tree.body:
        if isinstance(node, ast.Assign):
            found += [(node.lineno, t.id) for t in node.targets if isinstance(t, ast.Name)]
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            found.append((node.lineno, node.target.id))
        elif isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            found.append((node.lineno, node.name))
    return found


@cache
def _nodes(path: Path) -> tuple:
    tree = ast.parse(path.read_text())
    return tuple([("top", line, name) for line, name in _module_names(tree)] + list(ast.walk(tree)))


def where(matches) -> list[str]:
    """``path:line`` of each node of the sources' syntax trees for which ``matches(node)`` holds
    (a module's top-level names are visited as ``("top", line, name)`` tuples)."""
    found = []
    for path in sources():
        for node in _nodes(path):
            if matches(node):
                line = node[1] if isinstance(node, tuple) else node.lineno
                found.append(f"{path.relative_to(ROOT)}:{line}")
    return found


def top_level(name: str):
    """Matches a module's top-level assignment or definition of ``name``."""
    return lambda node: isinstance(node, tuple) and node[2] == name


def constant_tuple(*values: object):
    """Matches a tuple written out as the constants ``values``, e.g. ``(40, 110, 230)``."""
    return lambda node: (isinstance(node, ast.Tuple) and len(node.elts) == len(values)
                         and all(isinstance(e, ast.Constant) and e.value == v
                                 for e, v in zip(node.elts, values)))


def field_default(name: str, value: object):
    """Matches a class body's annotated field ``name: ... = value``."""
    return lambda node: (isinstance(node, ast.ClassDef) and any(
        isinstance(b, ast.AnnAssign) and isinstance(b.target, ast.Name) and b.target.id == name
        and isinstance(b.value, ast.Constant) and b.value.value == value for b in node.body))


def shift_of_one(node) -> bool:
    """``1 << 15`` ... ``1 << 19``: a chunk size written as a number."""
    return (isinstance(node, ast.BinOp) and isinstance(node.op, ast.LShift)
            and isinstance(node.left, ast.Constant) and node.left.value == 1
            and isinstance(node.right, ast.Constant) and node.right.value in range(15, 20))


def rounding_to_nine(node) -> bool:
    """``np.round(x, 9)``: a merge precision written as a number."""
    return (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
            and node.func.attr == "round" and len(node.args) == 2
            and isinstance(node.args[1], ast.Constant) and node.args[1].value == 9)


def helper_axis(node) -> bool:
    """``helper = np.where(...)``: the helper axis of an in-plane basis."""
    return (isinstance(node, ast.Assign) and any(
        isinstance(t, ast.Name) and t.id == "helper" for t in node.targets)
        and isinstance(node.value, ast.Call) and isinstance(node.value.func, ast.Attribute)
        and node.value.func.attr == "where")


@pytest.mark.slow
def test_protocol_and_split_names_are_spelled_only_in_dataset_protocols():
    spelled = []
    for path in sources():
        name = str(path.relative_to(ROOT))
        spelled += [f"{name}:{line} {value!r}" for line, value in code_strings(path)
                    if value in ("ideal", "multi", "train", "eval")]
    # the real photo sets' own train/val/test (segment.real_sets.common) are not scene splits
    allowed = ("envelope/protocols.py:", "segment/real_sets/common.py:")
    assert spelled and all(s.startswith(allowed) for s in spelled), spelled


@pytest.mark.slow
def test_the_class_palette_is_defined_once():
    # the class colours written out, e.g. (40, 110, 230), and the colour of unknown ids
    colours = sorted(set(where(constant_tuple(40, 110, 230)) + where(constant_tuple(200, 200, 200))
                         + where(constant_tuple(255, 0, 255))))
    assert len(colours) == 2 and all(c.startswith("envelope/classes.py:") for c in colours)


@pytest.mark.slow
def test_each_default_is_assigned_once():
    for name in ("MERGE_DECIMALS", "DEFAULT_CHUNK_POINTS", "scene_name", "CLASS_RGB",
                 "UNKNOWN_CLASS_RGB", "Split", "SPLITS", "PROTOCOLS"):
        assert len(where(top_level(name))) == 1, (name, where(top_level(name)))
    mesh_resolution = where(field_default("resolution", 256))
    assert len(mesh_resolution) == 1, mesh_resolution
    # face normals and in-plane bases: one helper each (envelope.mesh)
    for matches in (top_level("triangle_normals"), top_level("plane_bases"), helper_axis):
        assert len(where(matches)) == 1, where(matches)
    assert where(top_level("face_normals")) == []
    # no chunk size or merge precision written as a number elsewhere
    assert where(shift_of_one) == where(top_level("DEFAULT_CHUNK_POINTS"))
    assert where(rounding_to_nine) == []


def test_the_checks_see_what_they_look_for(tmp_path, monkeypatch):
    package = tmp_path / "dataset"
    package.mkdir()
    (package / "m.py").write_text(
        "CHUNK = 1 << 17\nX = np.round(v, 9)\nRGB = (40, 110, 230)\n"
        "class C:\n    resolution: int = 256\n"
        "def scene_name():\n    helper = np.where(a, b, c)\n")
    monkeypatch.setitem(globals(), "ROOT", tmp_path)
    monkeypatch.setitem(globals(), "PACKAGES", ("dataset",))
    assert where(shift_of_one) == where(top_level("CHUNK")) == ["dataset/m.py:1"]
    assert where(rounding_to_nine) == ["dataset/m.py:2"]
    assert where(constant_tuple(40, 110, 230)) == ["dataset/m.py:3"]
    assert where(field_default("resolution", 256)) == ["dataset/m.py:4"]
    assert where(top_level("scene_name")) == ["dataset/m.py:6"]
    assert where(helper_axis) == ["dataset/m.py:7"]


def test_the_check_sees_a_spelled_protocol(tmp_path):
    source = tmp_path / "m.py"
    source.write_text('"""Docstring: ideal."""\nX = {"train": 1}\nY = "multi"\n')
    assert code_strings(source) == [(3, "multi")]
