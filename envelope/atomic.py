"""Write files and folders so that a crash or Ctrl-C never leaves them half-written.

The temporary file or folder is made with ``os.open`` / ``os.mkdir`` asking for mode
0666 / 0777, so the user's umask decides the final mode as for any file they write (0644 and
0755 under umask 022); ``tempfile.mkstemp`` would keep its private 0600 (0700) through the
rename, leaving every result unreadable to everyone else.
"""

from __future__ import annotations

import json
import os
import shutil
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

_TRIES = 100  # names to try before giving up (each one a fresh random name)


def write_bytes_atomic(path: str | Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same folder and a rename."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp, fd = _make_sibling(path, ".tmp", lambda p: os.open(
        p, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0), 0o666))
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def write_text_atomic(path: str | Path, text: str) -> None:
    """Write UTF-8 text atomically (see :func:`write_bytes_atomic`)."""
    write_bytes_atomic(path, text.encode("utf-8"))


def write_json_atomic(path: str | Path, obj: Any) -> None:
    """Write ``obj`` as indented, key-ordered JSON atomically (byte-identical for equal input)."""
    write_text_atomic(path, json.dumps(obj, indent=2, sort_keys=False) + "\n")


@contextmanager
def atomic_directory(final: str | Path) -> Iterator[Path]:
    """Yield a temporary sibling folder; rename it to ``final`` only if the block succeeds.

    An existing ``final`` is replaced. On any exception (Ctrl-C included) the
    temporary folder is removed and ``final`` is left as it was.
    """
    final = Path(final)
    final.parent.mkdir(parents=True, exist_ok=True)
    tmp, _ = _make_sibling(final, ".partial", lambda p: os.mkdir(p, 0o777))
    try:
        yield tmp
        if final.exists():
            shutil.rmtree(final)
        os.replace(tmp, final)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def _make_sibling(final: Path, suffix: str, make: Callable[[Path], Any]) -> tuple[Path, Any]:
    """A new hidden ``.<name>.<random><suffix>`` beside ``final``, made by ``make(path)``
    (which raises ``FileExistsError`` if the path is taken); the path and what ``make``
    returned.

    Raises
    ------
    FileExistsError
        If every name tried was taken.
    """
    for _ in range(_TRIES):
        candidate = final.with_name(f".{final.name}.{os.urandom(6).hex()}{suffix}")
        try:
            return candidate, make(candidate)
        except FileExistsError:
            continue
    raise FileExistsError(f"no free temporary name beside {final} after {_TRIES} tries")
