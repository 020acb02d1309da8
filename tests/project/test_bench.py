"""bench/ has an index, and the tests keep out of it.

- bench/README.md names every bench script (``*.py``, ``*.sh``) in its table, and every
  measurement file it points to exists;
- no test imports from ``bench`` (a test of a bench script runs it as a command; what a test
  needs of a bench script belongs in a package).
"""

import ast
import re

from paths import REPO_ROOT

BENCH = REPO_ROOT / "bench"
ROW = re.compile(r"^\|\s*`([\w.-]+\.(?:py|sh))`\s*\|")
DOC_PATH = re.compile(r"(?<![\w/.-])(docs/[\w./-]+\.md)\b")


def scripts_listed(readme: str) -> set[str]:
    """The file names in the first cell of the README table's rows."""
    return {m.group(1) for line in readme.splitlines() if (m := ROW.match(line.strip()))}


def imports_bench(source: str) -> list[str]:
    """The ``bench`` modules a Python source imports (at any depth, ``import`` or ``from``)."""
    found = []
    for node in ast.walk(ast.parse(source)):
        names = ([a.name for a in node.names] if isinstance(node, ast.Import) else
                 [node.module] if isinstance(node, ast.ImportFrom) and node.module else [])
        found += [n for n in names if n == "bench" or n.startswith("bench.")]
    return found


def test_the_readme_lists_every_bench_script():
    on_disk = {p.name for p in BENCH.iterdir() if p.suffix in (".py", ".sh")}
    assert on_disk - scripts_listed((BENCH / "README.md").read_text()) == set()
    assert scripts_listed((BENCH / "README.md").read_text()) - on_disk == set()


def test_every_measurement_file_the_readme_names_exists():
    named = DOC_PATH.findall((BENCH / "README.md").read_text())
    assert named and [p for p in named if not (REPO_ROOT / p).is_file()] == []


def test_no_test_imports_bench():
    wrong = [f"{path.relative_to(REPO_ROOT)}: {module}"
             for path in sorted((REPO_ROOT / "tests").rglob("*.py"))
             for module in imports_bench(path.read_text())]
    assert wrong == []


def test_the_checks_see_a_missing_script_and_an_import():
    readme = "| script | what |\n|---|---|\n| `render.py` | speed |\n| `run.sh` | GPU |\n"
    assert scripts_listed(readme) == {"render.py", "run.sh"}
    source = ("import numpy\nfrom bench.oracle_measure import main\n"
              "def f():\n    import bench.neural3d\n")
    assert imports_bench(source) == ["bench.oracle_measure", "bench.neural3d"]
    assert imports_bench("from benchmarks import x\nimport benchmark\n") == []
