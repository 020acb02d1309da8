"""CityGML files as a source (:data:`CITYGML_SOURCE`): every building with a covered facade,
rendered by ``python -m dataset.generate --citygml FILE_OR_DIR``.

Reading imports every building of every file (without neighbours), so bad input is refused
before anything is written and buildings without a covered facade (no window or door
modelled) are left out with a message. The files given are one city model: each entry
re-imports its building when its scene has to be rendered, with the buildings of the files
near it as its neighbours (:func:`dataset.importers.citygml.context.files_near`; a picklable
partial of :func:`import_citygml_building`). The shipped Ingolstadt buildings are the
``lod3`` preset (:mod:`dataset.importers.citygml.preset`), read through the preset source.
"""

from __future__ import annotations

import sys
from functools import partial
from pathlib import Path

from tqdm import tqdm

from dataset.importers.citygml.buildings import benchmark_buildings
from dataset.importers.citygml.context import CityFile, file_bbox_m, files_near
from dataset.importers.citygml.convert import building_from_citygml, import_citygml_building
from dataset.importers.citygml.files import CityGmlError, citygml_files, is_citygml
from dataset.importers.citygml.read import read_citygml
from dataset.importers.source import BuildingEntry, NoOptions, Source
from envelope.provenance import file_fingerprint


def read_citygml_source(path: str | Path, options: NoOptions, *, progress: bool = True
                        ) -> tuple[BuildingEntry, ...]:
    """One entry per building with a covered facade, file by file (sorted), in file order.

    Raises
    ------
    CityGmlError (a ValueError)
        A file is not readable CityGML (the error names the file and the element), or no
        building of ``path`` has a window or door modelled.
    """
    files = citygml_files(path)
    models = [read_citygml(f) for f in tqdm(files, desc="CityGML", unit="file",
                                            disable=not progress or len(files) < 2)]
    city = [CityFile(f, file_bbox_m(m)) for f, m in zip(files, models)]
    fingerprints = {f: file_fingerprint(f) for f in files}
    entries = []
    for model, own in zip(models, city):
        near = files_near(own.bbox_m, city)
        for b in benchmark_buildings(model):
            if not building_from_citygml(model, b).truth.facades:
                print(f"{own.path}: building {b.gml_id} has no window or door modelled (no "
                      "covered facade): skipped", file=sys.stderr)
                continue
            entries.append(BuildingEntry(
                b.gml_id, partial(import_citygml_building, own.path, b.gml_id,
                                  neighbour_files=near),
                {"citygml": fingerprints[own.path], "building": b.gml_id,
                 "neighbours": [fingerprints[f] for f in near if f != own.path]}))
    if not entries:
        raise CityGmlError(f"{path}: no building with a window or door modelled; the "
                           "benchmark needs LoD3 openings (WallSurface with Window/Door)")
    names = [e.name for e in entries]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise CityGmlError(f"{path}: buildings of several files share the scene names "
                           f"{', '.join(twice)}; give the files one at a time or rename them")
    return tuple(entries)


CITYGML_SOURCE = Source(
    name="citygml", flag="--citygml",
    help="CityGML 2.0/3.0 LoD3 buildings: a .gml/.xml file (also .gz/.xz/.bz2) or a folder "
         "of them; one scene per Building/BuildingPart with a window or door modelled; see "
         "docs/importing.md section 8",
    detect=is_citygml, read=read_citygml_source,
)
