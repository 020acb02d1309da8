"""A small table type and its writers: CSV, Markdown, LaTeX and plain text for the terminal.

Cells are strings, numbers, :class:`~metrics.score.aggregate.Summary` (shown as
``mean ± std`` and, where it has one, its interval ``[low, high]``; columns
``<key>_mean`` and ``<key>_std``, and ``<key>_low``, ``<key>_high`` where any cell
of the column has an interval, in CSV) or ``None`` (a missing figure: an empty
CSV cell, an en dash elsewhere). Every file starts with a comment line saying
what produced it.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from envelope.atomic import write_text_atomic
from metrics.score.aggregate import Summary

Cell = str | int | float | Summary | None
MISSING = "–"
_LATEX_SPECIALS = {
    "\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#", "_": r"\_",
    "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}", "^": r"\textasciicircum{}",
    "±": r"$\pm$", "–": "--",
}


@dataclass(frozen=True)
class Table:
    """A table with display headers (``columns``) and machine names (``keys``) per column.

    ``name`` is the file stem; ``notes`` are printed under the table (e.g. why
    a run failed); ``decimals`` is the number of decimals of float cells.
    """

    name: str
    title: str
    columns: tuple[str, ...]
    keys: tuple[str, ...]
    rows: tuple[tuple[Cell, ...], ...]
    notes: tuple[str, ...] = ()
    decimals: int = 2

    def __post_init__(self) -> None:
        if len(self.columns) != len(self.keys):
            raise ValueError(
                f"table {self.name}: {len(self.columns)} column headers but {len(self.keys)} keys"
            )
        for i, row in enumerate(self.rows):
            if len(row) != len(self.columns):
                raise ValueError(
                    f"table {self.name}: row {i} has {len(row)} cells, expected {len(self.columns)}"
                )


def format_cell(cell: Cell, decimals: int) -> str:
    """Display text of one cell: ``mean ± std [low, high]`` for a summary (the std and the
    interval where it has them), an en dash for ``None``."""
    if cell is None:
        return MISSING
    if isinstance(cell, Summary):
        if cell.mean is None:
            return MISSING
        text = f"{cell.mean:.{decimals}f}"
        if cell.std is not None:
            text += f" ± {cell.std:.{decimals}f}"
        if cell.low is not None and cell.high is not None:
            text += f" [{cell.low:.{decimals}f}, {cell.high:.{decimals}f}]"
        return text
    if isinstance(cell, float):
        return f"{cell:.{decimals}f}"
    return str(cell)


def to_csv(table: Table, comment: str = "") -> str:
    """CSV text: ``# comment`` lines, a header of keys, rows, then ``# note:`` lines.

    Summaries expand to ``<key>_mean`` and ``<key>_std`` columns with full precision, and
    ``<key>_low``, ``<key>_high`` where any summary of the column has an interval.
    Read it back with :func:`read_csv_rows`.
    """
    summary_cols = {
        i for i, _ in enumerate(table.keys) if any(isinstance(r[i], Summary) for r in table.rows)
    }
    interval_cols = {
        i for i in summary_cols
        if any(isinstance(r[i], Summary) and r[i].low is not None for r in table.rows)
    }
    header: list[str] = []
    for i, key in enumerate(table.keys):
        header += [f"{key}_mean", f"{key}_std"] if i in summary_cols else [key]
        header += [f"{key}_low", f"{key}_high"] if i in interval_cols else []
    buf = io.StringIO()
    buf.write(_comment_lines("# ", comment))
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(header)
    for row in table.rows:
        out: list[str] = []
        for i, cell in enumerate(row):
            if i in summary_cols:
                s = cell if isinstance(cell, Summary) else Summary(None, None, 0)
                out += [_raw(s.mean), _raw(s.std)]
                out += [_raw(s.low), _raw(s.high)] if i in interval_cols else []
            else:
                out.append(_raw(cell))
        writer.writerow(out)
    buf.write(_comment_lines("# note: ", "\n".join(table.notes)))
    return buf.getvalue()


def read_csv_rows(text: str) -> list[dict[str, str]]:
    """Rows of a CSV written by :func:`to_csv` (comment lines skipped), as dicts of strings."""
    lines = [line for line in text.splitlines() if not line.startswith("#")]
    return list(csv.DictReader(lines))


def read_summary(row: dict[str, str], key: str) -> Summary:
    """The :class:`Summary` a row of :func:`read_csv_rows` holds for ``key`` (its ``_mean``,
    ``_std`` and, where written, ``_low``/``_high`` columns; count 0: not written)."""
    values = [row.get(f"{key}_{part}", "") for part in ("mean", "std", "low", "high")]
    mean, std, low, high = (float(v) if v else None for v in values)
    return Summary(mean, std, 0, low, high)


def to_markdown(table: Table, comment: str = "") -> str:
    """GitHub Markdown: an HTML comment, the bold title, the table and notes as a list."""
    cells = [[_md_escape(format_cell(c, table.decimals)) for c in row] for row in table.rows]
    lines = []
    if comment:
        lines.append(f"<!-- {comment.replace('--', '- -')} -->")
    lines += [
        f"**{table.title}**",
        "",
        "| " + " | ".join(_md_escape(c) for c in table.columns) + " |",
        "|" + "|".join("---" for _ in table.columns) + "|",
    ]
    lines += ["| " + " | ".join(row) + " |" for row in cells]
    if table.notes:
        lines.append("")
        lines += [f"- {_md_escape(n)}" for n in table.notes]
    return "\n".join(lines) + "\n"


def to_latex(table: Table, comment: str = "") -> str:
    """A LaTeX ``table`` float with a booktabs ``tabular`` (needs ``\\usepackage{booktabs}``)."""
    spec = "l" * _text_columns(table) + "r" * (len(table.columns) - _text_columns(table))
    lines = [_comment_lines("% ", comment).rstrip("\n")] if comment else []
    lines += [
        r"\begin{table}[t]",
        r"\centering",
        rf"\caption{{{latex_escape(table.title)}}}",
        rf"\label{{tab:{latex_escape(table.name)}}}",
        rf"\begin{{tabular}}{{{spec}}}",
        r"\toprule",
        " & ".join(latex_escape(c) for c in table.columns) + r" \\",
        r"\midrule",
    ]
    for row in table.rows:
        lines.append(
            " & ".join(latex_escape(format_cell(c, table.decimals)) for c in row) + r" \\"
        )
    lines += [r"\bottomrule", r"\end{tabular}"]
    if table.notes:
        lines.append(r"\par\smallskip\footnotesize")
        lines += [latex_escape(n) + r"\par" for n in table.notes]
    lines.append(r"\end{table}")
    return "\n".join(lines) + "\n"


def to_text(table: Table) -> str:
    """Aligned plain text for the terminal: title, header, rule, rows, notes."""
    cells = [[format_cell(c, table.decimals) for c in row] for row in table.rows]
    widths = [
        max([len(h)] + [len(r[i]) for r in cells]) for i, h in enumerate(table.columns)
    ]
    text_cols = _text_columns(table)

    def line(values: Sequence[str]) -> str:
        return "  ".join(
            v.ljust(w) if i < text_cols else v.rjust(w)
            for i, (v, w) in enumerate(zip(values, widths))
        ).rstrip()

    out = [table.title, line(table.columns), "  ".join("-" * w for w in widths)]
    out += [line(r) for r in cells]
    out += [f"  note: {n}" for n in table.notes]
    return "\n".join(out) + "\n"


def write_table(table: Table, folder: str | Path, comment: str = "") -> list[Path]:
    """Write ``<name>.csv``, ``<name>.md`` and ``<name>.tex`` atomically into ``folder``."""
    folder = Path(folder)
    paths = []
    for suffix, text in (
        (".csv", to_csv(table, comment)),
        (".md", to_markdown(table, comment)),
        (".tex", to_latex(table, comment)),
    ):
        path = folder / f"{table.name}{suffix}"
        write_text_atomic(path, text)
        paths.append(path)
    return paths


def latex_escape(text: str) -> str:
    """Escape LaTeX's special characters (``_`` -> ``\\_``, ``±`` -> ``$\\pm$``, ...)."""
    return "".join(_LATEX_SPECIALS.get(ch, ch) for ch in str(text))


def _raw(cell: Cell) -> str:
    if cell is None:
        return ""
    if isinstance(cell, float):
        return repr(cell)
    return str(cell)


def _md_escape(text: str) -> str:
    return str(text).replace("|", r"\|")


def _comment_lines(prefix: str, comment: str) -> str:
    return "".join(f"{prefix}{line}\n" for line in comment.splitlines() if line.strip())


def _text_columns(table: Table) -> int:
    """Number of leading columns holding labels (left-aligned); the rest hold figures."""
    for i in range(len(table.columns)):
        if any(isinstance(r[i], int | float | Summary) for r in table.rows):
            return i
    return len(table.columns)
