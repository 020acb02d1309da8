"""Each name and default is defined in one place: a grep over the project's sources shows it.

Protocol and split names, the class palette, the merge decimals, the field's chunk size, the
marching-cubes resolution, a scene's name, face normals and in-plane bases each have one
definition; everything else imports it. Read from the sources, not by importing.
"""

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("dataset", "baselines", "neural3d", "segment", "metrics", "figures")
# Importers that issue 17 works on at the same time as this check was written; their frame
# splits are converted to dataset.core.protocols' names when both branches meet.


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


def where(pattern: str) -> list[str]:
    """``path:line`` of each source line matching the regular expression ``pattern``."""
    found = []
    for path in sources():
        for number, line in enumerate(path.read_text().splitlines(), 1):
            if re.search(pattern, line):
                found.append(f"{path.relative_to(ROOT)}:{number}")
    return found


def test_protocol_and_split_names_are_spelled_only_in_dataset_protocols():
    spelled = []
    for path in sources():
        name = str(path.relative_to(ROOT))
        spelled += [f"{name}:{line} {value!r}" for line, value in code_strings(path)
                    if value in ("ideal", "multi", "train", "eval")]
    assert spelled and all(s.startswith("dataset/core/protocols.py:") for s in spelled), spelled


def test_the_class_palette_is_defined_once():
    # the class colours written out, e.g. (40, 110, 230), and the colour of unknown ids
    colours = where(r"\(\s*40,\s*110,\s*230\s*\)|\(\s*200,\s*200,\s*200\s*\)|"
                    r"\(\s*255,\s*0,\s*255\s*\)")
    assert len(colours) == 2 and all(c.startswith("dataset/core/classes.py:") for c in colours)


def test_each_default_is_assigned_once():
    for pattern in (r"^MERGE_DECIMALS\s*=", r"^DEFAULT_CHUNK_POINTS\s*=", r"^def scene_name\(",
                    r"^\s+resolution: int = 256", r"^CLASS_RGB\b", r"^UNKNOWN_CLASS_RGB\b",
                    r"^Split\s*=", r"^SPLITS\b", r"^PROTOCOLS\b"):
        assert len(where(pattern)) == 1, (pattern, where(pattern))
    # face normals and in-plane bases: one helper each (dataset.core.mesh)
    for pattern in (r"^def triangle_normals\(", r"^def plane_bases\(",
                    r"helper = np\.where\(np\.abs\(normals"):
        assert len(where(pattern)) == 1, (pattern, where(pattern))
    assert where(r"^def face_normals\(") == []
    # no chunk size or merge precision written as a number elsewhere
    assert where(r"\b1 << 1[5-9]\b") == where(r"^DEFAULT_CHUNK_POINTS\s*=")
    assert where(r"np\.round\([^)]*,\s*9\)") == []


def test_the_check_sees_a_spelled_protocol(tmp_path):
    source = tmp_path / "m.py"
    source.write_text('"""Docstring: ideal."""\nX = {"train": 1}\nY = "multi"\n')
    assert code_strings(source) == [(3, "multi")]
