"""The ``lod3`` preset's buildings: real LoD3 CityGML files shipped with the code.

``dataset/examples/lod3_ingolstadt/`` holds the Ingolstadt road-space models' buildings
that have at least one window (CC BY-SA 4.0, ``LICENSE`` and ``SOURCE.md`` there), one
xz-compressed CityGML 2.0 file each, and ``buildings.json``: one entry per building (scene
id, file, ``gml:id``), in scene order.

    python -m dataset.importers.citygml_preset SRC [--out dataset/examples/lod3_ingolstadt]

remakes the folder: ``SRC`` is ``models/building/lod3/individual/citygml`` of a clone of
https://github.com/savenow/lod3-road-space-models (the preset was made from commit
fdddf41d62c49282bf319b79b9f0a7b0ce1152b2). Every ``<id>/<id>.xml`` whose buildings model at
least one window is copied unchanged as ``<id>.xml.xz`` (xz preset 9e; textures are left
out), ``buildings.json`` lists each building with a covered facade in file order, and the
licence is copied beside them.
"""

from __future__ import annotations

import argparse
import json
import lzma
from dataclasses import dataclass
from pathlib import Path

from tqdm import tqdm

from dataset.core.atomic import write_bytes_atomic, write_text_atomic
from dataset.core.cli_errors import add_debug_flag, run_cli
from dataset.core.truth import Building
from dataset.importers.citygml_import import import_citygml, import_citygml_building
from dataset.importers.citygml_read import citygml_stem

LOD3_DIR = Path(__file__).resolve().parents[1] / "examples" / "lod3_ingolstadt"
MANIFEST = "buildings.json"
SOURCE_REPO = "https://github.com/savenow/lod3-road-space-models"
SOURCE_COMMIT = "fdddf41d62c49282bf319b79b9f0a7b0ce1152b2"


@dataclass(frozen=True)
class Lod3Entry:
    """One building of the shipped set: scene ``id``, ``file`` (name in :data:`LOD3_DIR`),
    its ``gml_id`` in that file and how many windows it models."""

    id: str
    file: str
    gml_id: str
    windows: int


def lod3_entries(folder: Path = LOD3_DIR) -> tuple[Lod3Entry, ...]:
    """The shipped buildings, in scene order.

    Raises
    ------
    ValueError
        The folder or its ``buildings.json`` is missing (a clone without the data).
    """
    path = Path(folder) / MANIFEST
    if not path.is_file():
        raise ValueError(f"{path} is missing: the lod3 preset's data is not in this checkout; "
                         "restore dataset/examples/lod3_ingolstadt from the repository")
    return tuple(Lod3Entry(**e) for e in json.loads(path.read_text())["buildings"])


def build_lod3_building(entry_id: str, file: str, folder: Path = LOD3_DIR) -> Building:
    """Import one shipped building (the same file, id and truth on every run).

    Raises
    ------
    ValueError
        The file does not hold a building of that id.
    """
    return import_citygml_building(Path(folder) / file, entry_id)


def make_lod3(src: Path, out: Path) -> list[dict]:
    """Copy the files with windows from ``src`` to ``out`` (xz) and write the manifest."""
    entries = []
    for path in tqdm(sorted(src.glob("*/*.xml")), desc="CityGML", unit="file"):
        buildings = [b for b in import_citygml(path) if b.truth.facades]
        if not buildings:
            continue
        name = f"{citygml_stem(path)}.xml.xz"
        write_bytes_atomic(out / name, lzma.compress(path.read_bytes(),
                                                     preset=9 | lzma.PRESET_EXTREME))
        for b in buildings:
            entries.append({"id": b.truth.id, "file": name, "gml_id": b.truth.extra["gml_id"],
                            "windows": b.truth.extra["counts"].get("window", 0)})
    write_text_atomic(out / MANIFEST, json.dumps(
        {"source": SOURCE_REPO, "commit": SOURCE_COMMIT, "licence": "CC BY-SA 4.0",
         "buildings": entries}, indent=1) + "\n")
    licence = src.parents[1] / "LICENSE"
    if licence.is_file():
        write_text_atomic(out / "LICENSE", licence.read_text())
    return entries


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="python -m dataset.importers.citygml_preset",
        description="Remake the lod3 preset's data folder (compressed CityGML files with a "
                    "window, buildings.json, LICENSE) from a clone of the source repository.")
    p.add_argument("src", type=Path, help="models/building/lod3/individual/citygml of a clone")
    p.add_argument("--out", type=Path, default=LOD3_DIR,
                   help=f"folder to write (default: {LOD3_DIR})")
    add_debug_flag(p)
    args = p.parse_args(argv)

    def body() -> int:
        if not args.src.is_dir():
            raise ValueError(f"{args.src} is not a folder; give the clone's "
                             "models/building/lod3/individual/citygml")
        args.out.mkdir(parents=True, exist_ok=True)
        entries = make_lod3(args.src, args.out)
        print(f"{len(entries)} buildings written to {args.out}")
        return 0

    return run_cli("dataset.importers.citygml_preset", body, debug=args.debug)


if __name__ == "__main__":
    raise SystemExit(main())
