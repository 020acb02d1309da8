"""docs/ARCHITECTURE.md names every module of the project's packages, and only those.

Each package is a table with one row per folder: the row's first cell is the folder in
backticks (``envelope/executors/``), its last cell names the folder's modules in backticks
(``__init__.py`` aside). Other backticked words of that cell (paths, dotted names, options)
carry a ``/``, a ``.`` or a ``-`` and are not read as module names.
"""

import re
from pathlib import Path

from paths import REPO_ROOT

PACKAGES = ("envelope", "dataset", "baselines", "neural3d", "segment", "metrics", "figures")
ARCHITECTURE = REPO_ROOT / "docs" / "ARCHITECTURE.md"
FOLDER_ROW = re.compile(r"^\|\s*`([\w/]+/)`\s*\|.*\|\s*$")
MODULE_NAME = re.compile(r"`([a-z_][a-z0-9_]*)`")


def modules_on_disk(root: Path) -> dict[str, set[str]]:
    """``{"pkg/sub/": {module stems}}`` for every folder of the packages that holds a module."""
    found: dict[str, set[str]] = {}
    for package in PACKAGES:
        for path in sorted((root / package).rglob("*.py")):
            if path.name == "__init__.py":
                continue
            folder = path.parent.relative_to(root).as_posix() + "/"
            found.setdefault(folder, set()).add(path.stem)
    return found


def modules_named(text: str) -> dict[str, set[str]]:
    """``{"pkg/sub/": {names}}``: the module names each folder's row gives in its last cell."""
    named: dict[str, set[str]] = {}
    for line in text.splitlines():
        m = FOLDER_ROW.match(line.strip())
        if m:
            last_cell = line.strip().rstrip("|").rsplit("|", 1)[1]
            named.setdefault(m.group(1), set()).update(MODULE_NAME.findall(last_cell))
    return named


def differences(on_disk: dict[str, set[str]], named: dict[str, set[str]]) -> list[str]:
    """What the doc misses (a module not named in its folder's row) and what it names that is
    not there (a module gone or moved, a folder without modules)."""
    out = []
    for folder in sorted(on_disk.keys() | named.keys()):
        disk, doc = on_disk.get(folder, set()), named.get(folder, set())
        out += [f"{folder}{stem}.py is not named in its row" for stem in sorted(disk - doc)]
        out += [f"{folder}: `{name}` is named but is no module there"
                for name in sorted(doc - disk)]
    return out


def test_architecture_names_every_module_and_no_other():
    assert differences(modules_on_disk(REPO_ROOT), modules_named(ARCHITECTURE.read_text())) == []


def test_the_check_sees_a_missing_and_a_stale_module(tmp_path):
    for path in ("envelope/wwr.py", "envelope/__init__.py", "metrics/run/runner.py",
                 "metrics/run/methods.py"):
        (tmp_path / path).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / path).write_text("")
    doc = ("| folder | what | modules |\n|---|---|---|\n"
           "| `envelope/` | contracts | `wwr` (see `docs/x.md`, `envelope.wwr`, --set) |\n"
           "| `metrics/run/` | running | `runner`, `executors` |\n")
    assert differences(modules_on_disk(tmp_path), modules_named(doc)) == [
        "metrics/run/methods.py is not named in its row",
        "metrics/run/: `executors` is named but is no module there"]
