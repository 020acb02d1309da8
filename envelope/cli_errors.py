"""How every command line ends: one line on stderr and a non-zero exit for bad input.

:func:`run_cli` runs a CLI's body and turns what a user can cause into one line:

| raised | printed | exit |
|---|---|---|
| ``ValueError`` (bad input, refused resources) | ``error: MESSAGE`` | 2 |
| ``OSError`` (unwritable folder, disk full, ...) | ``error: REASON: PATH`` | 1 |
| ``MemoryError`` | ``error: out of memory ...`` | 1 |
| ``KeyboardInterrupt`` (Ctrl-C, SIGTERM where the CLI maps it) | ``INTERRUPTED`` | 130 |
| anything else (a bug) | ``internal error in PROG: ...`` + how to see the traceback | 1 |

With ``--debug`` (:func:`add_debug_flag`) errors propagate with their traceback.
Python warnings raised during the run are collected and printed once per kind
at the end (:mod:`envelope.warnings_summary`), never once per face or frame.
"""

from __future__ import annotations

import argparse
import signal
import sys
import warnings
from collections.abc import Callable
from pathlib import Path

from envelope.warnings_summary import summarise_warnings

EXIT_BAD_INPUT = 2
EXIT_FAILED = 1
EXIT_INTERRUPTED = 130


def add_debug_flag(parser: argparse.ArgumentParser) -> None:
    """Add ``--debug``: show the Python traceback of an error instead of one line."""
    parser.add_argument("--debug", action="store_true",
                        help="show the full Python traceback of an error (for bug reports)")


def run_cli(prog: str, body: Callable[[], int], *, debug: bool = False,
            interrupted: str | Callable[[], str] = (
                "interrupted: finished outputs are kept, run again to resume")) -> int:
    """Run ``body`` and return its exit code; errors become one line on stderr (see module).

    ``interrupted`` is the line for Ctrl-C, or a function that says it once the run stopped.
    """
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            return body()
        except KeyboardInterrupt:
            _say(interrupted if isinstance(interrupted, str) else interrupted())
            return EXIT_INTERRUPTED
        except ValueError as exc:
            if debug:
                raise
            _say(f"error: {one_line(exc)}")
            return EXIT_BAD_INPUT
        except MemoryError:
            if debug:
                raise
            _say("error: out of memory; use smaller images, fewer views or workers, or "
                       "a lower resolution")
            return EXIT_FAILED
        except OSError as exc:
            if debug:
                raise
            _say(f"error: {os_error_line(exc)}")
            return EXIT_FAILED
        except Exception as exc:  # a bug: one line here, the traceback with --debug
            if debug:
                raise
            _say(f"internal error in {prog}: {type(exc).__name__}: {one_line(exc)} (a bug; rerun "
                       "with --debug for the traceback and report it)")
            return EXIT_FAILED
        finally:
            for line in summarise_warnings([str(w.message) for w in caught]):
                print(f"warning: {line}", file=sys.stderr)


def exit_cli(code: int) -> None:
    """Exit a command line with ``code`` (its ``__main__``: ``exit_cli(main())``).

    The work is done and written by now, so Ctrl-C is ignored from here on: during the
    interpreter's shutdown it would kill the process with no word (exit -2) or a stray
    traceback, and a finished run would look interrupted.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    sys.exit(code)


def check_output_folder(folder: str | Path, flag: str = "--out") -> Path:
    """Make sure ``folder`` can be created and written to, without creating it.

    Raises
    ------
    ValueError
        If it (or a parent) names an existing file, or its nearest existing parent
        folder cannot be written to.
    """
    import tempfile

    folder = Path(folder)
    existing = folder
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    if not existing.is_dir():
        what = "is an existing file" if existing == folder else f"is inside the file {existing}"
        raise ValueError(f"{flag} {folder} {what}, not a folder; name a folder")
    try:
        with tempfile.TemporaryFile(dir=existing):
            pass
    except OSError as exc:
        raise ValueError(f"cannot write to {flag} {folder}: {exc.strerror or exc} in "
                         f"{existing}; choose another {flag}") from exc
    return folder


def one_line(exc: BaseException) -> str:
    """The exception's message on one line (never empty)."""
    text = " ".join(str(exc).split())
    return text or type(exc).__name__


def os_error_line(exc: OSError) -> str:
    """``REASON: PATH`` of an OSError (``Permission denied: /data/x``)."""
    reason = exc.strerror or one_line(exc)
    return f"{reason}: {exc.filename}" if exc.filename else reason


def _say(text: str) -> None:
    print(text, file=sys.stderr)
