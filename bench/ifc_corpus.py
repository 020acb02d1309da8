"""Import every IFC model in a folder and check it against measures the importer does not use.

    python bench/ifc_corpus.py CORPUS_DIR [--spacing-m 0.1] [--json out.json]

Per file (``*.ifc``, or ``*.ifc.xz`` decompressed to a temporary file): the authoring tool and
schema from the header, the import time (:func:`dataset.importers.ifc.convert.read_ifc` and
:func:`~dataset.importers.ifc.convert.building_from_ifc`), the elements per class, the derived
window / wall / door areas, WWR and footprint -- or the error -- and three independent
measures:

- **declared windows**: the sum of ``OverallWidth x OverallHeight`` of the IfcWindows beside
  the measured area of the same windows (their window faces on a facade);
- **elevations** (:func:`dataset.importers.ifc.checks.elevation_areas`): the facade, window
  and WWR an architect would measure on orthographic elevation drawings;
- **plan** (:func:`dataset.importers.ifc.checks.plan_footprint`): the union of the plan
  projections of the elements that stand at the footprint height, beside the imported
  footprint (area and IoU).

The table is Markdown (docs/importing.md, "Real files"); timings are wall-clock on whatever
machine runs it.
"""

from __future__ import annotations

import argparse
import json
import lzma
import sys
import tempfile
import time
from pathlib import Path

sys.path[0] = str(Path(__file__).resolve().parent.parent)

from dataset.importers.ifc.checks import (  # noqa: E402
    elevation_areas,
    footprint_iou,
    plan_footprint,
)
from dataset.importers.ifc.convert import building_from_ifc, read_ifc  # noqa: E402
from dataset.importers.import_config import ImportConfig  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("corpus", type=Path, help="folder of .ifc / .ifc.xz files")
    parser.add_argument("--spacing-m", type=float, default=0.1,
                        help="ray spacing of the elevation measure (default 0.1 m)")
    parser.add_argument("--json", type=Path, help="also write the rows as JSON here")
    args = parser.parse_args(argv)
    files = sorted(p for p in args.corpus.iterdir() if p.name.endswith((".ifc", ".ifc.xz")))
    if not files:
        print(f"error: no .ifc or .ifc.xz file in {args.corpus}", file=sys.stderr)
        return 2
    rows = []
    print(HEADER)
    for path in files:
        row = measure_file(path, args.spacing_m)
        rows.append(row)
        print(format_row(row), flush=True)
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))
    ok = sum(r["result"] == "ok" for r in rows)
    print(f"\n{ok} of {len(rows)} files import.")
    return 0


HEADER = ("| file | tool | schema | time s | elements (wall/window/door/roof/other) | "
          "result | window m² (declared IfcWindow: declared / measured) | wall m² | door m² | "
          "WWR | elevations: facade m², window m², WWR | footprint m² | plan m² (IoU) |\n"
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|")


def measure_file(path: Path, spacing_m: float) -> dict:
    """Import one file and measure it (module docstring); errors become the row's result."""
    with tempfile.TemporaryDirectory() as tmp:
        ifc = path
        if path.name.endswith(".xz"):
            ifc = Path(tmp) / path.name[:-3]
            ifc.write_bytes(lzma.decompress(path.read_bytes()))
        row = {"file": path.name, **_header(ifc)}
        start = time.perf_counter()
        try:
            model = read_ifc(ifc, progress=False)
            building = building_from_ifc(model, ifc, config=ImportConfig())
        except ValueError as exc:
            row.update(result=f"error: {exc}", time_s=time.perf_counter() - start)
            return row
        row["time_s"] = time.perf_counter() - start
    t = building.truth
    record = t.extra["ifc"]
    declared = [w for w in record["windows"] if w["declared_area_m2"]]
    row.update(
        result="ok", elements=record["elements"], warnings=record["warnings"],
        skipped=len(record["skipped"]), ground=record["ground"],
        window_m2=t.window_area_m2, wall_m2=t.wall_area_m2, door_m2=t.door_area_m2,
        facade_m2=t.facade_area_m2, wwr=t.wwr, footprint_m2=t.footprint_area_m2,
        declared_window_m2=sum(w["declared_area_m2"] for w in declared),
        measured_declared_window_m2=sum(w["measured_area_m2"] for w in declared),
        n_windows=len(record["windows"]),
        elevations=elevation_areas(building.mesh, spacing_m),
    )
    plan = plan_footprint(model, t.extra["ground_z_m"] + ImportConfig().footprint_height_m)
    row["plan_m2"] = float(plan.area)
    row["plan_iou"] = footprint_iou(plan, t)
    return row


def _header(path: Path) -> dict:
    """Authoring tool and schema from the file's header."""
    import ifcopenshell

    model = ifcopenshell.open(str(path))
    name = model.header.file_name
    tool = " / ".join(x for x in (name.originating_system, name.preprocessor_version) if x)
    return {"tool": tool, "schema": model.schema}


def format_row(r: dict) -> str:
    if r["result"] != "ok":
        return (f"| {r['file']} | {r['tool'][:60]} | {r['schema']} | {r['time_s']:.1f} | | "
                f"{r['result'][:300]} | | | | | | | |")
    e = r["elements"]
    counts = "/".join(str(e.get(k, 0)) for k in ("wall", "window", "door", "roof", "other"))
    el = r["elevations"]
    declared = (f"{r['declared_window_m2']:.2f} / {r['measured_declared_window_m2']:.2f} "
                f"({r['measured_declared_window_m2'] / r['declared_window_m2'] - 1:+.1%})"
                if r["declared_window_m2"] else "none declared")
    return (f"| {r['file']} | {r['tool'][:60]} | {r['schema']} | {r['time_s']:.1f} | {counts} | "
            f"ok{', ' + str(r['skipped']) + ' skipped' if r['skipped'] else ''} | "
            f"{r['window_m2']:.2f} ({declared}) | {r['wall_m2']:.1f} | {r['door_m2']:.2f} | "
            f"{r['wwr']:.4f} | {el['facade_m2']:.1f}, {el['window_m2']:.2f}, {el['wwr']:.4f} | "
            f"{r['footprint_m2']:.1f} | {r['plan_m2']:.1f} ({r['plan_iou']:.3f}) |")


if __name__ == "__main__":
    sys.exit(main())
