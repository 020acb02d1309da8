"""Per-facade WWR error in percentage points, the figure practitioners quote; prints Markdown.

    python bench/wwr_points.py --data data/lod3 [--results data/lod3-results] [--out FILE]

For every result file in ``--results`` (as ``metrics.compare`` writes them) whose scene has
a ``building.json`` in ``--data``, each truth facade the result names is paired with its
estimate (:func:`metrics.errors.facade_errors`: facade ids under the ideal/multi views,
matched by position for neural3d). Per method and view protocol: facades, the mean
absolute WWR difference in points (100 x |WWR_est - WWR_true|), and the share of facades
within 5 and within 10 points (Suppa et al. 2025's street-view figure), over every facade of
the truth: one a method failed on or has no view of counts as outside both and is listed
as failed. For the CityGML
scenes the truth's facades are the covered ones (docs/importing.md, section 8).
"""

from __future__ import annotations

import argparse
import sys
from collections import defaultdict
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from dataset.core.results import read_result  # noqa: E402
from dataset.core.truth import read_building  # noqa: E402
from metrics.errors import facade_errors  # noqa: E402

BANDS_POINTS = (5.0, 10.0)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--data", type=Path, required=True)
    p.add_argument("--results", type=Path)
    p.add_argument("--out", type=Path)
    args = p.parse_args()
    results = args.results or args.data.with_name(args.data.name + "-results")
    rows: dict[tuple[str, str], list[float | None]] = defaultdict(list)
    scenes: dict[tuple[str, str], set[str]] = defaultdict(set)
    for path in sorted(results.glob("*.json")):
        result = read_result(path)
        truth_path = args.data / result.scene / "building.json"
        if not truth_path.is_file():
            continue
        truth = read_building(truth_path)
        key = (result.method, result.protocol)
        scenes[key].add(result.scene)
        named = set()
        for f in facade_errors(result, truth):
            if f.facade_id == 0 or f.facade_id in named:
                continue  # an estimate on no truth facade: not a facade of the truth
            named.add(f.facade_id)
            ok = f.status == "ok" and f.wwr_est is not None
            rows[key].append(100 * abs(f.wwr_est - f.wwr_true) if ok else None)
        # A truth facade the result does not name (no view of it) counts as failed.
        rows[key].extend([None] * len({t.id for t in truth.facades} - named))
    lines = ["| method | views | buildings | facades | failed | mean abs WWR error (points) | "
             + " | ".join(f"within ±{b:g}" for b in BANDS_POINTS) + " |",
             "|---|---|---:|---:|---:|---:|" + "---:|" * len(BANDS_POINTS)]
    for (method, protocol), diffs in sorted(rows.items()):
        done = [d for d in diffs if d is not None]
        mean = sum(done) / len(done) if done else float("nan")
        shares = [sum(d <= b for d in done) / len(diffs) for b in BANDS_POINTS]
        lines.append(f"| {method} | {protocol} | {len(scenes[(method, protocol)])} | "
                     f"{len(diffs)} | {len(diffs) - len(done)} | {mean:.2f} | "
                     + " | ".join(f"{s:.0%}" for s in shares) + " |")
    text = "\n".join(lines)
    print(text)
    if args.out:
        args.out.write_text(text + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
