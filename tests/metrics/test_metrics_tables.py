"""Table writers: parseable CSV, Markdown, structurally valid LaTeX, aligned text."""

import csv
import io
import re

import pytest

from metrics.report.tables import (
    Table,
    latex_escape,
    read_csv_rows,
    to_csv,
    to_latex,
    to_markdown,
    to_text,
    write_table,
)
from metrics.score.aggregate import Summary

TABLE = Table(
    name="t_1",
    title="Errors of l_shaped & co (100% sure)",
    columns=("Family", "Method", "n", "WWR error (%)", "IoU"),
    keys=("family", "method", "n", "wwr_ape", "iou"),
    rows=(
        ("l_shaped", "2D-S", 2, Summary(15.0, 5.0, 2), 0.5),
        ("all", "neural3d", 1, Summary(None, None, 0), None),
    ),
    notes=("failed: l_shaped / 2D-SS / ideal: c: corrupt {file}",),
)
COMMENT = "produced by a test\nsecond line"


def test_csv_parses_with_the_csv_module_and_keeps_full_precision():
    text = to_csv(TABLE, COMMENT)
    assert text.startswith("# produced by a test\n# second line\n")
    assert text.rstrip().endswith("# note: failed: l_shaped / 2D-SS / ideal: c: corrupt {file}")
    data = [line for line in text.splitlines() if not line.startswith("#")]
    rows = list(csv.reader(io.StringIO("\n".join(data))))
    assert rows[0] == ["family", "method", "n", "wwr_ape_mean", "wwr_ape_std", "iou"]
    assert rows[1] == ["l_shaped", "2D-S", "2", "15.0", "5.0", "0.5"]
    assert rows[2] == ["all", "neural3d", "1", "", "", ""]
    assert read_csv_rows(text)[0]["wwr_ape_std"] == "5.0"


def test_markdown_has_one_row_per_table_row_and_the_notes():
    md = to_markdown(TABLE, COMMENT)
    lines = md.splitlines()
    assert lines[0].startswith("<!-- produced by a test")
    assert "| l_shaped | 2D-S | 2 | 15.00 ± 5.00 | 0.50 |" in lines
    assert "| all | neural3d | 1 | – | – |" in lines
    assert sum(line.startswith("|") for line in lines) == 2 + len(TABLE.rows)
    assert lines[-1].startswith("- failed: l_shaped")


def test_latex_is_balanced_and_escaped():
    tex = to_latex(TABLE, COMMENT)
    assert tex.startswith("% produced by a test\n% second line\n")
    body = "\n".join(line for line in tex.splitlines() if not line.startswith("%"))
    for env in ("table", "tabular"):
        assert body.count(rf"\begin{{{env}}}") == body.count(rf"\end{{{env}}}") == 1
    unescaped = re.compile(r"(?<!\\)[_&%#]")
    # Outside the column separators, no special character may stay unescaped.
    for line in body.splitlines():
        cells = line.split(" & ") if line.endswith(r"\\") else [line]
        for cell in cells:
            assert not unescaped.search(cell), line
    assert r"l\_shaped" in body and r"100\% sure" in body and r"l\_shaped \& co" in body
    assert r"15.00 $\pm$ 5.00" in body and r"corrupt \{file\}" in body
    assert _braces_balanced(body)
    assert re.search(r"\\begin\{tabular\}\{llrrr\}", body)
    assert body.count(r"\\") >= 1 + len(TABLE.rows)


def test_latex_escape_every_special():
    assert latex_escape("a_b&c%d$e#f{g}h~i^j\\") == (
        r"a\_b\&c\%d\$e\#f\{g\}h\textasciitilde{}i\textasciicircum{}j\textbackslash{}"
    )


def test_text_is_aligned():
    lines = to_text(TABLE).splitlines()
    assert lines[0] == TABLE.title
    header_end = lines[1].index("WWR error (%)") + len("WWR error (%)")
    assert lines[3].index("± 5.00") + len("± 5.00") == header_end  # figures right-aligned
    assert lines[4].index("–") + 1 == header_end
    assert lines[3].split() == ["l_shaped", "2D-S", "2", "15.00", "±", "5.00", "0.50"]
    assert lines[-1].startswith("  note: failed:")


def test_write_table_writes_three_files(tmp_path):
    paths = write_table(TABLE, tmp_path, COMMENT)
    assert [p.name for p in paths] == ["t_1.csv", "t_1.md", "t_1.tex"]
    assert all(p.read_text() for p in paths)


def test_bad_tables():
    with pytest.raises(ValueError, match="2 column headers but 1 keys"):
        Table("x", "x", ("a", "b"), ("a",), ())
    with pytest.raises(ValueError, match="row 0 has 1 cells, expected 2"):
        Table("x", "x", ("a", "b"), ("a", "b"), (("only",),))


def _braces_balanced(text: str) -> bool:
    depth = 0
    for i, ch in enumerate(text):
        if ch in "{}" and i > 0 and text[i - 1] == "\\":
            continue
        depth += {"{": 1, "}": -1}.get(ch, 0)
        if depth < 0:
            return False
    return depth == 0
