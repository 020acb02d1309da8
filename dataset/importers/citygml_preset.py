"""The ``lod3`` preset's buildings: real LoD3 CityGML files shipped with the code.

``dataset/examples/lod3_ingolstadt/`` holds the Ingolstadt road-space models' buildings
that have at least one window (CC BY-SA 4.0, ``LICENSE`` and ``SOURCE.md`` there), one
xz-compressed CityGML 2.0 file each, and ``buildings.json``: one entry per building (scene
id, file, ``gml:id``), in scene order. ``python -m dataset.examples.make_lod3 SRC`` remakes
the folder from a clone of the source repository.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from dataset.core.truth import Building
from dataset.importers.citygml_import import import_citygml_building

LOD3_DIR = Path(__file__).resolve().parents[1] / "examples" / "lod3_ingolstadt"
MANIFEST = "buildings.json"


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
