"""Summarise warnings: one line per kind with a count, never one per face or frame.

Two warnings are of the same kind when they differ only in words that hold a
digit or a path (file names, ids, counts, scene names): ``view images/ideal_0003.png
(facade 3) skipped: ...`` and ``view images/ideal_0007.png (facade 5) skipped: ...``.
"""

from __future__ import annotations

import re
from collections.abc import Iterable

_VARIABLE_WORD = re.compile(r"[^\s]*[\d/\\][^\s]*")


def warning_kind(message: str) -> str:
    """The message with every word that holds a digit or a path replaced by ``#``."""
    return _VARIABLE_WORD.sub("#", " ".join(message.split()))


def summarise_warnings(messages: Iterable[str]) -> list[str]:
    """One line per kind, in order of first appearance: the first message, plus a count.

    ``["a 1", "a 2", "b"]`` -> ``["a 1 (2 warnings like this)", "b"]``.
    """
    first: dict[str, str] = {}
    count: dict[str, int] = {}
    for message in messages:
        kind = warning_kind(message)
        first.setdefault(kind, " ".join(message.split()))
        count[kind] = count.get(kind, 0) + 1
    return [first[k] if count[k] == 1 else f"{first[k]} ({count[k]} warnings like this)"
            for k in first]
