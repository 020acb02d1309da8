"""One building, two ways in: each IFC model imported as IFC and as the labelled mesh it exports.

    python bench/ifc_mesh_agreement.py [FOLDER] [--formats ply,obj] [--json rows.json]

Per ``*.ifc`` / ``*.ifc.xz`` file of FOLDER (default: the committed fixtures,
``tests/fixtures/ifc_real``): the IFC import (:func:`dataset.importers.ifc.convert.read_ifc`,
:func:`~dataset.importers.ifc.convert.building_from_ifc`), then the same triangulation written
as a labelled mesh, one body per element (:mod:`dataset.importers.ifc.mesh_export`), and
imported back with the mesh importer at the IFC's ground (``--ground-z``, as a user gives a
mesh without storeys). Prints, per path, the window and facade areas, the WWR, the bodies
found (closed / all) and the relative difference from the IFC import. Markdown
(docs/measurements/ifc-mesh-agreement.md).
"""

from __future__ import annotations

import argparse
import json
import lzma
import sys
import tempfile
from pathlib import Path

sys.path[0] = str(Path(__file__).resolve().parent.parent)

from dataset.importers.ifc.convert import building_from_ifc, read_ifc  # noqa: E402
from dataset.importers.ifc.mesh_export import write_model_mesh  # noqa: E402
from dataset.importers.import_config import ImportConfig  # noqa: E402
from dataset.importers.mesh.mesh_import import import_labelled_mesh  # noqa: E402

FIXTURES = Path(__file__).resolve().parent.parent / "tests" / "fixtures" / "ifc_real"
HEADER = ("| file | path | window m² | facade m² | WWR | bodies closed / all "
          "| window vs IFC | facade vs IFC | WWR vs IFC |\n|---|---|---|---|---|---|---|---|---|")


def measure_file(path: Path, formats: list[str], folder: Path) -> list[dict]:
    """Rows for one IFC file: the IFC import, then each exported format imported back."""
    ifc = folder / path.name.removesuffix(".xz")
    if path.name.endswith(".xz"):
        ifc.write_bytes(lzma.decompress(path.read_bytes()))
    else:
        ifc.write_bytes(path.read_bytes())
    model = read_ifc(ifc, progress=False)
    rows = [_row(ifc.name, "ifc", building_from_ifc(model, ifc).truth)]
    for fmt in formats:
        written = write_model_mesh(model, folder / f"{ifc.stem}.{fmt}")
        truth = import_labelled_mesh(
            written.path, config=ImportConfig(ground_z_m=written.ground_z_m)).truth
        rows.append(_row(ifc.name, fmt, truth))
    return rows


def _row(name: str, path: str, truth) -> dict:
    bodies = truth.extra["bodies"]
    return {"file": name, "path": path, "window_m2": truth.window_area_m2,
            "facade_m2": truth.facade_area_m2, "wwr": truth.wwr,
            "bodies": bodies["bodies"], "closed": bodies["closed"]}


def markdown_row(row: dict, ifc: dict) -> str:
    def rel(key: str) -> str:
        if row is ifc:
            return ""
        percent = 100 * (row[key] / ifc[key] - 1)
        return "0.00 %" if abs(percent) < 0.005 else f"{percent:+.2f} %"

    return (f"| {row['file']} | {row['path']} | {row['window_m2']:.2f} | "
            f"{row['facade_m2']:.2f} | {row['wwr']:.4f} | {row['closed']} / {row['bodies']} | "
            f"{rel('window_m2')} | {rel('facade_m2')} | {rel('wwr')} |")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("folder", type=Path, nargs="?", default=FIXTURES,
                        help="folder of .ifc / .ifc.xz files (default: the test fixtures)")
    parser.add_argument("--formats", default="ply,obj",
                        help="mesh layouts to export and import back (default ply,obj)")
    parser.add_argument("--json", type=Path, help="also write the rows as JSON here")
    args = parser.parse_args(argv)
    files = sorted(p for p in args.folder.iterdir() if p.name.endswith((".ifc", ".ifc.xz")))
    if not files:
        print(f"error: no .ifc or .ifc.xz file in {args.folder}", file=sys.stderr)
        return 2
    formats = [f.strip() for f in args.formats.split(",") if f.strip()]
    rows: list[dict] = []
    print(HEADER)
    with tempfile.TemporaryDirectory() as tmp:
        for path in files:
            file_rows = measure_file(path, formats, Path(tmp))
            for row in file_rows:
                print(markdown_row(row, file_rows[0]), flush=True)
            rows += file_rows
    if args.json:
        args.json.write_text(json.dumps(rows, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
