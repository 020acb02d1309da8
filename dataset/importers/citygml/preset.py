"""The ``lod3`` preset's buildings: real LoD3 CityGML files shipped with the code.

``dataset/examples/lod3_ingolstadt/`` holds the Ingolstadt road-space models' buildings
(CC BY-SA 4.0, ``LICENSE`` and ``SOURCE.md`` there) in the source's layout: one
xz-compressed CityGML 2.0 file per folder, ``<id>/<id>.xml.xz``, with the textures it names
in ``<id>/textures/`` (downscaled), and ``buildings.json``: the scene buildings (scene id,
file, ``gml:id``, window count; every building with a covered facade, in scene order) and
every file with its bounding box (the neighbours of ``--context`` and of the party-wall
rule are the files near a building, :mod:`dataset.importers.citygml.context`). The city's road
network, ``road_network/*.xodr.xz`` (OpenDRIVE, CC BY-NC-SA 4.0, its own ``LICENSE``), gives
every building its streets (the lanes ``--street`` drives, :mod:`dataset.importers.
opendrive_streets`).

    python -m dataset.importers.citygml.preset SRC [--out dataset/examples/lod3_ingolstadt]

remakes the folder: ``SRC`` is ``models/building/lod3/individual/citygml`` of a clone of
https://github.com/savenow/lod3-road-space-models (the preset was made from commit
fdddf41d62c49282bf319b79b9f0a7b0ce1152b2). Every ``<id>/<id>.xml`` is copied unchanged as
``<id>/<id>.xml.xz`` (xz preset 9e), each texture it names as a JPEG of at most
:data:`TEXTURE_MAX_PX` pixels a side (quality :data:`TEXTURE_QUALITY`), and the licence
beside them.
"""

from __future__ import annotations

import argparse
import json
import lzma
from dataclasses import dataclass, replace
from pathlib import Path

from tqdm import tqdm

from dataset.importers.citygml.buildings import benchmark_buildings
from dataset.importers.citygml.context import CityFile, file_bbox_m, files_near
from dataset.importers.citygml.convert import building_from_citygml, import_citygml_building
from dataset.importers.citygml.files import citygml_stem
from dataset.importers.citygml.read import read_citygml
from dataset.importers.opendrive.streets import streets_in_frame
from envelope.atomic import write_bytes_atomic, write_text_atomic
from envelope.cli_errors import add_debug_flag, run_cli
from envelope.truth import Building

LOD3_DIR = Path(__file__).resolve().parents[2] / "examples" / "lod3_ingolstadt"
MANIFEST = "buildings.json"
ROAD_NETWORK = LOD3_DIR / "road_network" / (
    "2021-04-22_HD21_529_Intersections_CityHall_Ingolstadt.xodr.xz")
"""The source's ``models/road-network/opendrive/`` file of that name, xz-compressed."""
SOURCE_REPO = "https://github.com/savenow/lod3-road-space-models"
SOURCE_COMMIT = "fdddf41d62c49282bf319b79b9f0a7b0ce1152b2"
TEXTURE_MAX_PX = 256
"""Longest side of a shipped texture: the models' textures tile every 0.1-2 m, so 256 pixels
are finer than a 512-pixel view of a facade (about 4 cm a pixel) ever samples."""
TEXTURE_QUALITY = 85  # JPEG quality of the shipped textures


@dataclass(frozen=True)
class Lod3Entry:
    """One building of the shipped set: scene ``id``, ``file`` (name in :data:`LOD3_DIR`),
    its ``gml_id`` in that file and how many windows it models."""

    id: str
    file: str
    gml_id: str
    windows: int


def lod3_entries(folder: Path = LOD3_DIR) -> tuple[Lod3Entry, ...]:
    """The shipped scene buildings, in scene order.

    Raises
    ------
    ValueError
        The folder or its ``buildings.json`` is missing (a clone without the data).
    """
    return tuple(Lod3Entry(**e) for e in _manifest(folder)["buildings"])


def lod3_files(folder: Path = LOD3_DIR) -> tuple[CityFile, ...]:
    """Every shipped file (scene buildings' and neighbours' alone) with its bounding box."""
    folder = Path(folder)
    return tuple(CityFile(folder / f["file"], tuple(f["bbox_m"]))
                 for f in _manifest(folder)["files"])


def build_lod3_building(entry_id: str, file: str, folder: Path = LOD3_DIR) -> Building:
    """Import one shipped building with its neighbours and, where the folder has the road
    network, its streets (the same truth on every run).

    Raises
    ------
    ValueError
        The file does not hold a building of that id.
    """
    files = lod3_files(folder)
    (own,) = [f for f in files if f.path == Path(folder) / file]
    building = import_citygml_building(own.path, entry_id,
                                       neighbour_files=files_near(own.bbox_m, files))
    roads = Path(folder) / ROAD_NETWORK.relative_to(LOD3_DIR)
    if not roads.is_file():
        return building
    return replace(building, streets=streets_in_frame(
        roads, building.truth.extra["crs"], building.truth.extra["offset_m"]))


def make_lod3(src: Path, out: Path) -> list[dict]:
    """Copy every file of ``src`` to ``out`` (xz, textures downscaled); write the manifest."""
    entries, files = [], []
    for path in tqdm(sorted(src.glob("*/*.xml")), desc="CityGML", unit="file"):
        model = read_citygml(path)
        name = f"{citygml_stem(path)}/{citygml_stem(path)}.xml.xz"
        write_bytes_atomic(out / name, lzma.compress(path.read_bytes(),
                                                     preset=9 | lzma.PRESET_EXTREME))
        for uri in sorted({look.image_uri for look in model.looks.values() if look.image_uri}):
            if (path.parent / uri).is_file():
                write_bytes_atomic((out / name).parent / uri, _small_jpeg(path.parent / uri))
        files.append({"file": name, "bbox_m": [round(x, 3) for x in file_bbox_m(model)]})
        for b in benchmark_buildings(model):
            building = building_from_citygml(model, b)
            if building.truth.facades:
                entries.append({"id": b.gml_id, "file": name,
                                "gml_id": building.truth.extra["gml_id"],
                                "windows": building.truth.extra["counts"].get("window", 0)})
    write_text_atomic(out / MANIFEST, json.dumps(
        {"source": SOURCE_REPO, "commit": SOURCE_COMMIT, "licence": "CC BY-SA 4.0",
         "buildings": entries, "files": files}, indent=1) + "\n")
    licence = src.parents[1] / "LICENSE"
    if licence.is_file():
        write_text_atomic(out / "LICENSE", licence.read_text())
    return entries


def _manifest(folder: Path) -> dict:
    path = Path(folder) / MANIFEST
    if not path.is_file():
        raise ValueError(f"{path} is missing: the lod3 preset's data is not in this checkout; "
                         "restore dataset/examples/lod3_ingolstadt from the repository")
    return json.loads(path.read_text())


def _small_jpeg(path: Path) -> bytes:
    """The image at ``path`` as a JPEG of at most :data:`TEXTURE_MAX_PX` pixels a side."""
    import io

    from PIL import Image

    with Image.open(path) as im:
        im = im.convert("RGB")
        im.thumbnail((TEXTURE_MAX_PX, TEXTURE_MAX_PX), Image.Resampling.LANCZOS)
        buf = io.BytesIO()
        im.save(buf, "JPEG", quality=TEXTURE_QUALITY, optimize=True)
    return buf.getvalue()


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="python -m dataset.importers.citygml.preset",
        description="Remake the lod3 preset's data folder (compressed CityGML files, their "
                    "textures downscaled, buildings.json, LICENSE) from a clone of the source "
                    "repository.")
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

    return run_cli("dataset.importers.citygml.preset", body, debug=args.debug)


if __name__ == "__main__":
    raise SystemExit(main())
