"""Every figure the README and the docs quote from a results folder is in that folder's
committed tables, and the folder is not older than the code it depends on unless the text
says so (:mod:`metrics.publish`).

A quoting block starts with a marker line ``<!-- figures: docs/measurements/tables/NAME -->``
(``<!-- figures: ... (earlier code) -->`` where the code has changed since) and runs to the
next blank line; each decimal number in it must equal a value of the folder's CSV files
rounded to the decimals quoted.
"""

import csv
import re
from functools import cache
from pathlib import Path

import pytest
from paths import REPO_ROOT

from metrics.publish import read_record, stale_code

MARKER = re.compile(r"^<!-- figures: (\S+)( \(earlier code[^)]*\))? -->$")  # a line of its own
DECIMAL = re.compile(r"(?<![\w.])-?\d+\.\d+(?![\w.])")
DOCS = sorted([REPO_ROOT / "README.md", *(REPO_ROOT / "docs").rglob("*.md")])


def quoting_blocks(text: str) -> list[tuple[str, bool, str]]:
    """(folder, says earlier code, block text) for each marker in ``text``."""
    lines = text.splitlines()
    out = []
    for i, line in enumerate(lines):
        m = MARKER.match(line.strip())
        if not m:
            continue
        block = []
        for follow in lines[i + 1:]:
            if not follow.strip():
                break
            block.append(follow)
        out.append((m.group(1), m.group(2) is not None, "\n".join(block)))
    return out


@cache
def table_values(folder: Path) -> tuple[float, ...]:
    """Every number in the folder's CSV files (comment lines skipped)."""
    values = []
    for path in sorted(folder.glob("*.csv")):
        rows = [r for r in path.read_text().splitlines() if not r.startswith("#")]
        for row in csv.reader(rows):
            for cell in row:
                try:
                    values.append(float(cell))
                except ValueError:
                    continue
    return tuple(values)


def quoted_but_absent(block: str, values: tuple[float, ...]) -> list[str]:
    """The decimal numbers of ``block`` that no value rounds to (at the decimals quoted)."""
    missing = []
    for text in DECIMAL.findall(block):
        decimals = len(text.split(".")[1])
        if not any(f"{v:.{decimals}f}" == text for v in values):
            missing.append(text)
    return missing


BLOCKS = [(doc, *b) for doc in DOCS for b in quoting_blocks(doc.read_text())]


def test_the_readme_quotes_a_results_folder():
    assert any(doc.name == "README.md" for doc, *_ in BLOCKS)


@pytest.mark.parametrize(("doc", "folder", "earlier", "block"), BLOCKS,
                         ids=[f"{d.relative_to(REPO_ROOT)}:{f}" for d, f, _, _ in BLOCKS])
def test_quoted_figures_are_in_the_committed_tables(doc, folder, earlier, block):
    path = REPO_ROOT / folder
    assert (path / "RECORD.json").is_file(), f"{doc.name} quotes {folder}, which has no record"
    absent = quoted_but_absent(block, table_values(path))
    assert not absent, f"{doc.name} quotes {absent} under {folder}, not in its tables"
    stale = stale_code(read_record(path))
    assert earlier or not stale, (
        f"{folder} was made by earlier code ({', '.join(sorted(stale))} changed since): "
        f"republish it (python -m metrics.publish) or say '(earlier code)' in {doc.name}'s "
        "marker")


def test_the_check_catches_a_number_that_is_not_there():
    values = (1.0234, 0.97512, 14.36)
    assert quoted_but_absent("WWR 1.0 % and IoU 0.98, 14.4 %", values) == []
    assert quoted_but_absent("WWR 1.1 % and IoU 0.975", values) == ["1.1"]
    blocks = quoting_blocks("a\n<!-- figures: x/y (earlier code, 2026-11-28) -->\n"
                            "one 1.5\ntwo\n\nafter 2.5")
    assert blocks == [("x/y", True, "one 1.5\ntwo")]
