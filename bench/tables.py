"""The bench scripts' Markdown tables, printed through ``metrics``' own table type
(:class:`metrics.report.tables.Table`, :func:`metrics.report.tables.to_markdown`), so that
the project writes a table one way.

Cells are the text each script formats (each column with its own decimals); a bench script
builds the rows and this module lays them out.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence

from metrics.report.tables import Table, to_markdown


def markdown_table(title: str, columns: Sequence[str], rows: Iterable[Sequence[object]]) -> str:
    """A GitHub Markdown table under its bold title, without a trailing newline.

    ``columns``: the headers; ``rows``: one sequence of cells per row, each as long as
    ``columns`` (cells are shown as ``str`` gives them).

    Raises
    ------
    ValueError
        If a row has another number of cells than ``columns``.
    """
    name = re.sub(r"[^a-z0-9]+", "_", title.lower()).strip("_") or "table"
    table = Table(name=name, title=title, columns=tuple(columns), keys=tuple(columns),
                  rows=tuple(tuple(str(c) for c in row) for row in rows))
    return to_markdown(table).rstrip("\n")
