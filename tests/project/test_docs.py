"""The docs name only what exists: every project file path, every bare file name and every dotted
name in README.md and docs/*.md resolves (docs/decisions.md is dated history and keeps the names
of its day, as does docs/DESIGN.md, the design contract as it was given, and the files under
docs/measurements/, which the glob below does not reach)."""

import ast
import re
from functools import cache
from pathlib import Path

import pytest
from paths import REPO_ROOT

ROOT = REPO_ROOT
PACKAGES = ("envelope", "dataset", "baselines", "neural3d", "segment", "metrics", "figures")
FOLDERS = (*PACKAGES, "tests", "bench", "scripts", "docs")
DOCS = sorted(p for p in [ROOT / "README.md", *(ROOT / "docs").glob("*.md")]
              if p.name not in {"decisions.md", "DESIGN.md"})
PATH = re.compile(rf"(?<![\w/.-])((?:{'|'.join(FOLDERS)})/[\w./-]*\.(?:py|md|png|sh|json))\b")
# a file name without its folder (`errors.py`, DESIGN.md); not one of another repository's files
# cited with its line (`cameramanager.py:21`), which the doc names with that repository
BARE = re.compile(r"(?<![\w/.<>{}*$-])([\w-]+\.(?:py|md|sh))(?![\w/]|:\d)")
DOTTED = re.compile(rf"(?<![\w./-])((?:{'|'.join(PACKAGES)})(?:\.\w+)+)")


@cache
def defined_names(path: Path) -> frozenset[str]:
    """Names a module defines or imports at any depth (functions, classes, assignments)."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, (ast.Assign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            for target in targets:
                names |= {n.id for n in ast.walk(target) if isinstance(n, ast.Name)}
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names |= {(a.asname or a.name).split(".")[0] for a in node.names}
    return frozenset(names)


def resolves(dotted: str) -> bool:
    """``pkg.module[.name]``: the longest importable prefix exists and defines the next part."""
    parts = dotted.split(".")
    for k in range(len(parts), 0, -1):
        base = ROOT.joinpath(*parts[:k])
        source = base.with_suffix(".py") if base.with_suffix(".py").is_file() else (
            base / "__init__.py")
        if source.is_file():
            return k == len(parts) or parts[k] in defined_names(source)
    return False


def references(doc: Path, pattern: re.Pattern) -> list[tuple[int, str]]:
    return [(number, m.group(1).rstrip("."))
            for number, line in enumerate(doc.read_text().splitlines(), 1)
            for m in pattern.finditer(line)]


def prose_lines(text: str) -> list[tuple[int, str]]:
    """(line number, line) outside fenced code blocks (commands and examples the reader
    types, whose file names are theirs to make)."""
    out, fenced = [], False
    for number, line in enumerate(text.splitlines(), 1):
        if line.lstrip().startswith("```"):
            fenced = not fenced
        elif not fenced:
            out.append((number, line))
    return out


def bare_names(text: str) -> list[tuple[int, str]]:
    return [(number, m.group(1)) for number, line in prose_lines(text)
            for m in BARE.finditer(line)]


@cache
def repository_file_names() -> frozenset[str]:
    """The names of the files in the project's folders and at its top."""
    names = {p.name for p in ROOT.iterdir() if p.is_file()}
    for folder in FOLDERS:
        names |= {p.name for p in (ROOT / folder).rglob("*") if "__pycache__" not in p.parts}
    return frozenset(names)


@pytest.mark.parametrize("doc", DOCS, ids=lambda p: p.name)
def test_every_path_in_the_docs_exists(doc):
    # relative to the repository, or to the page (docs/figures/... from docs/*.md)
    missing = [f"{doc.name}:{n}: {path}" for n, path in references(doc, PATH)
               if not (ROOT / path).exists() and not (doc.parent / path).exists()]
    assert missing == []


@pytest.mark.parametrize("doc", DOCS, ids=lambda p: p.name)
def test_every_bare_file_name_in_the_docs_exists_somewhere(doc):
    missing = [f"{doc.name}:{n}: {name}" for n, name in bare_names(doc.read_text())
               if name not in repository_file_names()]
    assert missing == []


@pytest.mark.parametrize("doc", DOCS, ids=lambda p: p.name)
def test_every_dotted_name_in_the_docs_resolves(doc):
    stale = [f"{doc.name}:{n}: {name}" for n, name in references(doc, DOTTED)
             if not resolves(name)]
    assert stale == []


def test_the_checks_see_a_stale_name():
    assert resolves("envelope.wwr.wwr_from_areas")
    assert not resolves("envelope.wwr.no_such_function")
    assert not resolves("dataset.cameras")
    assert PATH.findall("see `neural3d/device.py` and envelope/wwr.py.") == [
        "neural3d/device.py", "envelope/wwr.py"]
    text = ("see `errors.py`, DESIGN.md and `cameramanager.py:21`; docs/ARCHITECTURE.md\n"
            "```\npython -m segment.evaluate_real --out report.md\n```\n")
    assert bare_names(text) == [(1, "errors.py"), (1, "DESIGN.md")]
    assert "errors.py" in repository_file_names()
    assert "DESIGN.md" in repository_file_names()  # docs/DESIGN.md, the contract's copy
