"""Train, validation and test photos of the real sets: a fixed rule, and committed lists.

A photo's split follows from its **group** (the photos that may show the same building,
:class:`segment.real_sets.common.RealPhoto`), never from a random generator's order:
``position = sha256("<SALT>/<set>/<group>")`` read as a number in [0, 1), then

- CMP: every ``extended`` facade is ``test``; a ``base`` facade is ``test`` below 0.25,
  ``val`` below 0.40, ``train`` above;
- LabelMeFacade: ``test`` below 0.35 (only the photos of LabelMeFacade's own ``test.txt``:
  a photo of such a group in its ``train.txt`` is ``none``, used by nothing, so no
  training photo shares a street session with a test photo), ``val`` below 0.50,
  ``train`` above.

The lists ``splits/<set>.csv`` (``name,group,part,split``) are this rule written out for
every photo of the copies read (2026-11-28) and are what :func:`split_of` reads; a test
checks that they agree with the rule. A photo missing from the list belongs to no split,
except a CMP ``extended`` facade (test by the rule: no copy of the extended set was at
hand when the lists were written). Nothing trains, or is chosen, on ``test``.

``python -m segment.real_sets.splits --labelmefacade DIR --cmp DIR`` rewrites the lists.
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import io
from collections import Counter
from collections.abc import Sequence
from pathlib import Path

from envelope.atomic import write_text_atomic
from envelope.cli_errors import add_debug_flag, exit_cli, run_cli
from segment.real_sets import SET_NAMES, RealPhoto, read_set
from segment.real_sets.common import PHOTO_SPLITS, PHOTO_TEST, PHOTO_TRAIN, PHOTO_VAL

SALT = "envelope-bench real-photo splits 2026-11-28"
NONE = "none"
"""Split of a photo used by nothing (LabelMeFacade ``train.txt`` photo of a test group)."""
TEST_BELOW = {"labelmefacade": 0.35, "cmp": 0.25}
VAL_BELOW = {"labelmefacade": 0.50, "cmp": 0.40}
LIST_DIR = Path(__file__).resolve().parent / "splits"
_COLUMNS = ("name", "group", "part", "split")


def group_position(set_name: str, group: str) -> float:
    """A group's place in [0, 1): the first 8 bytes of sha256 of ``SALT/set/group``."""
    digest = hashlib.sha256(f"{SALT}/{set_name}/{group}".encode()).digest()
    return int.from_bytes(digest[:8], "big") / 2.0**64


def split_rule(photo: RealPhoto) -> str:
    """The split the rule (module doc) gives ``photo``: train, val, test or none."""
    if photo.set_name == "cmp" and photo.part == "extended":
        return "test"
    position = group_position(photo.set_name, photo.group)
    if position < TEST_BELOW[photo.set_name]:
        if photo.set_name == "labelmefacade" and photo.part != "test":
            return NONE
        return PHOTO_TEST
    return PHOTO_VAL if position < VAL_BELOW[photo.set_name] else PHOTO_TRAIN


def committed_splits(set_name: str, list_dir: Path = LIST_DIR) -> dict[str, str]:
    """Photo name -> split, from the committed list of ``set_name``.

    Raises
    ------
    ValueError
        A missing or malformed list.
    """
    path = list_dir / f"{set_name}.csv"
    if not path.is_file():
        raise ValueError(f"no split list {path}; write it with `python -m "
                         f"segment.real_sets.splits`")
    rows = list(csv.DictReader(io.StringIO(path.read_text())))
    if not rows or tuple(rows[0]) != _COLUMNS:
        raise ValueError(f"{path}: expected columns {','.join(_COLUMNS)}")
    bad = [r["name"] for r in rows if r["split"] not in (*PHOTO_SPLITS, NONE)]
    if bad:
        raise ValueError(f"{path}: unknown split for {bad[:3]}")
    return {r["name"]: r["split"] for r in rows}


def split_of(photo: RealPhoto, committed: dict[str, str]) -> str:
    """``photo``'s split from the committed list (``none`` when unlisted, except a CMP
    ``extended`` facade: test)."""
    if photo.name in committed:
        return committed[photo.name]
    return "test" if photo.set_name == "cmp" and photo.part == "extended" else NONE


def split_list_text(photos: Sequence[RealPhoto]) -> str:
    """CSV text of the rule's split of every photo, sorted by name."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(_COLUMNS)
    for p in sorted(photos, key=lambda p: p.name):
        writer.writerow([p.name, p.group, p.part, split_rule(p)])
    return out.getvalue()


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m segment.real_sets.splits",
        description="Write the committed split lists (segment/real_sets/splits/<set>.csv) "
        "of the real sets from the fixed rule, and print how many photos each split holds.")
    for name in SET_NAMES:
        parser.add_argument(f"--{name}", type=Path, help=f"a copy of {name}")
    parser.add_argument("--out", type=Path, default=LIST_DIR,
                        help=f"folder of the lists (default: {LIST_DIR})")
    add_debug_flag(parser)
    args = parser.parse_args(argv)

    def body() -> int:
        given = {n: getattr(args, n) for n in SET_NAMES if getattr(args, n) is not None}
        if not given:
            flags = ", ".join(f"--{n}" for n in SET_NAMES)
            raise ValueError(f"give at least one set folder ({flags})")
        for name, root in given.items():
            photos = read_set(name, root)
            write_text_atomic(args.out / f"{name}.csv", split_list_text(photos))
            counts = Counter(split_rule(p) for p in photos)
            groups = {s: len({p.group for p in photos if split_rule(p) == s}) for s in counts}
            print(f"{name}: " + ", ".join(f"{s} {counts[s]} photos ({groups[s]} groups)"
                                          for s in (*PHOTO_SPLITS, NONE) if s in counts))
        return 0

    return run_cli("segment.real_sets.splits", body, debug=args.debug)


if __name__ == "__main__":
    exit_cli(main())
