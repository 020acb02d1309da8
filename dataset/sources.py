"""Every way a building or a scene enters the benchmark: :data:`SOURCES`, the one list.

``python -m dataset.generate`` offers one option per source flag (``--preset``, ``--mesh``,
``--ifc``, ``--buildnet3d``, ``--citygml``, ``--photos``) and ``--input PATH``, which takes
the first source in this order that detects PATH. A new source (a reader of another format) is
declared beside its reader as a :class:`dataset.importers.source.Source` and added here; the
command line then offers it (:mod:`dataset.source_args`). The procedural presets are declared
here because :mod:`dataset.presets` sits above :mod:`dataset.importers` in the data flow.
"""

from __future__ import annotations

from functools import partial
from pathlib import Path

from dataset.importers.buildnet3d.blenderproc import BLENDERPROC_SOURCE
from dataset.importers.buildnet3d.buildnet3d import BUILDNET3D_SOURCE
from dataset.importers.citygml.source import CITYGML_SOURCE
from dataset.importers.mesh.building_file import IFC_SOURCE, MESH_SOURCE
from dataset.importers.photos.source import PHOTOS_SOURCE
from dataset.importers.source import BuildingEntry, NoOptions, Source


def preset_names() -> tuple[str, ...]:
    """The built-in presets' names (:data:`dataset.presets.PRESETS`)."""
    from dataset.presets import PRESETS

    return tuple(PRESETS)


def read_preset(name: str | Path, options: NoOptions) -> tuple[BuildingEntry, ...]:
    """One building entry per recipe of preset ``name``: scene ``recipe.id``, the recipe's
    seed, built by :func:`dataset.presets.build_building`.

    Raises
    ------
    ValueError
        Unknown preset.
    """
    from dataset.presets import build_building, preset_recipes

    return tuple(BuildingEntry(r.id, partial(build_building, r),
                               {"preset": str(name), "recipe": r.id}, seed=r.seed)
                 for r in preset_recipes(str(name)))


PRESET_SOURCE = Source(
    name="preset", flag="--preset", help="a built-in set of procedural buildings",
    detect=lambda name: isinstance(name, str) and name in preset_names(), read=read_preset,
    choices=preset_names,
)
SOURCES: tuple[Source, ...] = (PRESET_SOURCE, MESH_SOURCE, IFC_SOURCE, BLENDERPROC_SOURCE,
                               BUILDNET3D_SOURCE, CITYGML_SOURCE, PHOTOS_SOURCE)
"""Every source, in the order ``--input`` tries them (the BlenderProc layout before the
Blender generator's: a folder of either is told apart by its ``meta_data.json``; CityGML
after them: its files are told apart by their root element, a folder by its first file;
photos last: any folder holding a JPEG or PNG is one)."""
