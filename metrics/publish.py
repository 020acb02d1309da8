"""``python -m metrics.publish``: keep a comparison's tables as committed results files.

Every figure the README or the docs quote comes from a folder this command wrote
(``docs/measurements/tables/<name>/``): the comparison's numeric tables (CSV and Markdown),
its per-building and per-facade CSVs, and ``RECORD.json`` (:class:`PublishedRecord`: the
command that made them, the code fingerprints of every package they depend on, the date).
A doc quotes a folder with a marker line ``<!-- figures: docs/measurements/tables/<name> -->``
before the paragraph or table that quotes it; ``tests/project/test_quoted_figures.py`` checks
that every number there is in the folder's tables and that the folder is not older than
the code, unless the marker says ``earlier code``.
"""

from __future__ import annotations

import argparse
import json
import shutil
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path

from envelope.atomic import atomic_directory, write_json_atomic
from envelope.cli_errors import exit_cli, run_cli
from envelope.provenance import code_fingerprint

RECORD_FILE = "RECORD.json"
TABLES_ROOT = Path("docs/measurements/tables")
NUMERIC_SUFFIXES = (".csv", ".md")
SCORING_CODE = ("metrics",)  # the scoring and aggregation every table goes through
SKIPPED = ("timing.csv",)  # differs between reruns: not a result


@dataclass(frozen=True)
class PublishedRecord:
    """What made a published folder: ``produced_by`` (the comparison's command),
    ``code_version`` (its git commit), ``created_utc``, ``data`` (the benchmark's name),
    ``code`` (package -> fingerprint, for the methods' code and :data:`SCORING_CODE`)."""

    produced_by: str
    code_version: str
    created_utc: str
    data: str
    code: dict[str, str]


def record_of(compare_out: Path) -> PublishedRecord:
    """The record of a comparison's output folder, from its ``provenance.json``.

    Raises
    ------
    ValueError
        If the folder has no ``provenance.json`` (not a comparison's output).
    """
    path = compare_out / "provenance.json"
    if not path.is_file():
        raise ValueError(f"{compare_out} has no provenance.json: give the --out folder of "
                         "`python -m metrics.compare`")
    prov = json.loads(path.read_text())
    code: dict[str, str] = {}
    for run in prov.get("runs", ()):
        code.update((run.get("provenance") or {}).get("code", {}))
    code.update({m: code_fingerprint(m) for m in SCORING_CODE})
    return PublishedRecord(prov["produced_by"], prov["code_version"], prov["created_utc"],
                           Path(prov["data"]).name, dict(sorted(code.items())))


def stale_code(record: PublishedRecord) -> dict[str, tuple[str, str]]:
    """Package -> (published, current) fingerprint where the code has changed since."""
    out = {}
    for module, published in record.code.items():
        try:
            current = code_fingerprint(module)
        except ValueError:
            current = "absent"
        if current != published:
            out[module] = (published, current)
    return out


def read_record(folder: Path) -> PublishedRecord:
    """The :class:`PublishedRecord` of a published folder.

    Raises
    ------
    ValueError
        If the folder has no readable record.
    """
    try:
        return PublishedRecord(**json.loads((folder / RECORD_FILE).read_text()))
    except (OSError, ValueError, TypeError) as exc:
        raise ValueError(f"{folder}: no readable {RECORD_FILE} ({exc}); publish it with "
                         "`python -m metrics.publish`") from exc


def publish(compare_out: Path, folder: Path) -> list[Path]:
    """Replace ``folder`` with the numeric tables of ``compare_out`` and their record;
    return the files written (sorted)."""
    record = record_of(compare_out)
    files = sorted(p for p in compare_out.iterdir()
                   if p.is_file() and p.suffix in NUMERIC_SUFFIXES and p.name not in SKIPPED)
    if not files:
        raise ValueError(f"{compare_out} holds no table (CSV or Markdown)")
    with atomic_directory(folder) as tmp:
        for p in files:
            shutil.copyfile(p, tmp / p.name)
        write_json_atomic(tmp / RECORD_FILE, asdict(record))
    return sorted(folder.iterdir())


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m metrics.publish",
        description="Copy a comparison's tables (CSV, Markdown), per-building and per-facade "
                    "CSVs into a committed results folder with a RECORD.json (command, code "
                    "fingerprints, date). Example: python -m metrics.publish --from "
                    ".cache/envelope-bench/tiny-compare --name default")
    parser.add_argument("--from", dest="source", type=Path, required=True,
                        help="the --out folder of `python -m metrics.compare`")
    parser.add_argument("--name", required=True,
                        help=f"the results folder's name, under {TABLES_ROOT}/")
    parser.add_argument("--root", type=Path, default=TABLES_ROOT,
                        help=f"where results folders live (default {TABLES_ROOT})")
    args = parser.parse_args(argv)

    def body() -> int:
        written = publish(args.source, args.root / args.name)
        print(f"wrote {len(written)} files to {args.root / args.name}")
        return 0

    return run_cli("metrics.publish", body)


if __name__ == "__main__":
    exit_cli(main())
