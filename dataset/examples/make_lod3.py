"""Make ``lod3_ingolstadt/``: the lod3 preset's CityGML files, compressed, with a manifest.

    python -m dataset.examples.make_lod3 SRC [--out dataset/examples/lod3_ingolstadt]

``SRC`` is ``models/building/lod3/individual/citygml`` of a clone of
https://github.com/savenow/lod3-road-space-models (CC BY-SA 4.0; the preset was made from
commit fdddf41d62c49282bf319b79b9f0a7b0ce1152b2). Every ``<id>/<id>.xml`` whose buildings
model at least one window is copied unchanged as ``<id>.xml.xz`` (xz preset 9e; textures
are left out), and ``buildings.json`` lists each building that has a covered facade (scene
id, file, ``gml:id``, windows) in file order. The licence and source note are written
beside them.
"""

from __future__ import annotations

import argparse
import json
import lzma
import sys
from pathlib import Path

from dataset.core.atomic import write_bytes_atomic, write_text_atomic
from dataset.importers.citygml_import import import_citygml
from dataset.importers.citygml_preset import LOD3_DIR, MANIFEST
from dataset.importers.citygml_read import citygml_stem

SOURCE_REPO = "https://github.com/savenow/lod3-road-space-models"
SOURCE_COMMIT = "fdddf41d62c49282bf319b79b9f0a7b0ce1152b2"


def make_lod3(src: Path, out: Path) -> list[dict]:
    """Copy the files with windows from ``src`` to ``out`` (xz) and write the manifest."""
    entries = []
    for path in sorted(src.glob("*/*.xml")):
        buildings = [b for b in import_citygml(path) if b.truth.facades]
        if not buildings:
            continue
        name = f"{citygml_stem(path)}.xml.xz"
        write_bytes_atomic(out / name, lzma.compress(path.read_bytes(),
                                                     preset=9 | lzma.PRESET_EXTREME))
        for b in buildings:
            entries.append({"id": b.truth.id, "file": name, "gml_id": b.truth.extra["gml_id"],
                            "windows": b.truth.extra["counts"].get("window", 0)})
        print(f"{name}: {', '.join(b.truth.id for b in buildings)}", file=sys.stderr)
    write_text_atomic(out / MANIFEST, json.dumps(
        {"source": SOURCE_REPO, "commit": SOURCE_COMMIT, "licence": "CC BY-SA 4.0",
         "buildings": entries}, indent=1) + "\n")
    licence = src.parents[1] / "LICENSE"
    if licence.is_file():
        write_text_atomic(out / "LICENSE", licence.read_text())
    return entries


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m dataset.examples.make_lod3",
                                description=__doc__.splitlines()[0])
    p.add_argument("src", type=Path, help="models/building/lod3/individual/citygml of a clone")
    p.add_argument("--out", type=Path, default=LOD3_DIR)
    args = p.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    entries = make_lod3(args.src, args.out)
    print(f"{len(entries)} buildings written to {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
