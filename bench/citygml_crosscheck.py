"""The CityGML importer's truth against the renderer's labels, per building; prints Markdown.

    python bench/citygml_crosscheck.py FILE_OR_DIR [...] [--pixel-m 0.02] [--out FILE]

For every building of the CityGML files given (``.xml``/``.gml``/``.gml.gz``/``.xml.gz``),
import it (:func:`dataset.importers.citygml.convert.import_citygml`) and render each covered
facade head-on (:func:`dataset.importers.citygml.crosscheck.check_facades`): the window and
gross areas back-projected from the facade-only render ("bare") and from the whole mesh
("seen": installations, roofs and other walls in front hide part of it) against the
truth. Lists every building whose bare window or gross area differs by more than 2 %, and
the five with the largest differences, with import time per building.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from dataset.importers.citygml.convert import import_citygml  # noqa: E402
from dataset.importers.citygml.crosscheck import PIXEL_M, check_facades  # noqa: E402
from dataset.importers.citygml.files import citygml_files  # noqa: E402

AGREE = 0.02


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("paths", nargs="+", type=Path)
    p.add_argument("--pixel-m", type=float, default=PIXEL_M)
    p.add_argument("--out", type=Path, help="also write the Markdown here")
    args = p.parse_args()
    rows = []
    for path in [f for x in args.paths for f in citygml_files(x)]:
        t0 = time.perf_counter()
        buildings = import_citygml(path)
        t_import = (time.perf_counter() - t0) / max(1, len(buildings))
        for b in buildings:
            if not b.truth.facades:
                continue
            checks = check_facades(b, pixel_m=args.pixel_m)
            rows.append(_row(b, checks, t_import))
            print(_line(rows[-1]), file=sys.stderr, flush=True)
    lines = [
        f"CityGML cross-check, pixel {args.pixel_m * 100:.0f} cm, {len(rows)} buildings with a "
        "covered facade",
        "",
        "| building | facades | window m² | bare window | bare gross | seen window | seen gross"
        " | hidden by (m²) | installation polygons | import s |",
        "|---|---:|---:|---:|---:|---:|---:|---|---:|---:|",
    ]
    lines += [_line(r) for r in rows]
    off = [r for r in rows if max(abs(r["bare_window"]), abs(r["bare_gross"])) > AGREE]
    lines += ["", f"bare render off by more than {AGREE:.0%}: "
              + (", ".join(r["id"] for r in off) or "none")]
    worst = sorted(rows, key=lambda r: -max(abs(r["bare_window"]), abs(r["bare_gross"])))[:5]
    lines += ["five largest bare differences: " + ", ".join(
        f"{r['id']} ({max(abs(r['bare_window']), abs(r['bare_gross'])):.2%})" for r in worst)]
    worst_seen = sorted(rows, key=lambda r: -abs(r["seen_gross"]))[:5]
    lines += ["five most hidden (seen gross): " + ", ".join(
        f"{r['id']} ({r['seen_gross']:+.2%})" for r in worst_seen)]
    text = "\n".join(lines)
    print(text)
    if args.out:
        args.out.write_text(text + "\n")
    return 0


def _row(building, checks, t_import: float) -> dict:
    def total(attr: str, key: str) -> float:
        return sum(sum(getattr(c, attr).values()) if key == "gross" else getattr(c, attr)[key]
                   for c in checks)

    hidden: dict[str, float] = {}
    for c in checks:
        for k, v in c.hidden_by_m2.items():
            hidden[k] = hidden.get(k, 0.0) + v
    row = {"id": building.truth.id, "facades": len(checks),
           "window": total("truth_m2", "window"), "t": t_import,
           "hidden": ", ".join(f"{k} {v:.1f}" for k, v in sorted(hidden.items(),
                                                                 key=lambda kv: -kv[1])),
           "installations": building.truth.extra["counts"].get("installation", 0)}
    for key in ("window", "gross"):
        truth = total("truth_m2", key)
        for attr, name in (("bare_m2", "bare"), ("rendered_m2", "seen")):
            row[f"{name}_{key}"] = (total(attr, key) - truth) / truth if truth else 0.0
    return row


def _line(r: dict) -> str:
    return (f"| {r['id']} | {r['facades']} | {r['window']:.1f} | {r['bare_window']:+.2%} | "
            f"{r['bare_gross']:+.2%} | {r['seen_window']:+.2%} | {r['seen_gross']:+.2%} | "
            f"{r['hidden']} | {r['installations']} | {r['t']:.1f} |")


if __name__ == "__main__":
    raise SystemExit(main())
