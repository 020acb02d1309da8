"""One way in: a :class:`Source` turns a path (or a preset's name) into scene entries.

Every way a building or a scene enters the benchmark is a :class:`Source` with the same two
calls: ``detect(path)`` (is ``path`` of this kind?) and ``read(path, options)`` (the entries
it holds, ``options`` an instance of the source's frozen ``options_type``). An entry is
either

- a :class:`BuildingEntry`: a building (labelled mesh + exact truth) that
  ``python -m dataset.generate`` renders into a scene folder, resumably (a labelled mesh,
  an IFC model, a procedural preset's buildings, a CityGML file's buildings), or
- a :class:`SceneEntry`: a scene an official generator has already rendered, written as a
  project scene folder by :func:`write_scenes` (the BuildNet3D layouts).

The one list of sources is :data:`dataset.sources.SOURCES`; the sources are declared beside
their readers (:mod:`dataset.importers.mesh.building_file`,
:mod:`dataset.importers.buildnet3d.buildnet3d`,
:mod:`dataset.importers.buildnet3d.blenderproc`, :mod:`dataset.sources` for the presets). A source
reads no command line: its options are a typed frozen dataclass, which
:mod:`dataset.source_args` builds from the command line once.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tqdm import tqdm

from envelope.atomic import atomic_directory
from envelope.truth import Building


@dataclass(frozen=True)
class BuildingEntry:
    """A building that a source gives, to be rendered into the scene folder ``name``.

    ``build()`` makes the building; it is called only when the scene has to be rendered,
    perhaps in a worker process or on a Ray node, so it must pickle (a module-level function
    or a ``functools.partial`` of one). ``inputs`` records what the scene is made from (file
    fingerprints, recipe, import options) in its provenance: a rerun skips a finished scene
    whose record matches. ``seed``: the building's own seed, mixed with the run's seed
    (``None``: the run's seed as it is).
    """

    name: str
    build: Callable[[], Building]
    inputs: Mapping[str, Any]
    seed: int | None = None


@dataclass(frozen=True)
class SceneEntry:
    """A scene that a source gives already rendered: ``write(folder)`` writes it as a project
    scene folder (``transforms.json``, images, and ``building.json`` where the source has a
    truth) into the empty temporary ``folder`` that becomes ``name``."""

    name: str
    write: Callable[[Path], object]


Entry = BuildingEntry | SceneEntry


@dataclass(frozen=True)
class NoOptions:
    """The options of a source that takes none."""


@dataclass(frozen=True)
class Source:
    """One way in for buildings or scenes (module docstring).

    ``name``: short and unique in the list. ``flag``: the option of
    ``python -m dataset.generate`` that names this source's paths; sources that share one
    (the two official BuildNet3D layouts) are told apart by ``detect``. ``help``: what a path
    of this source is, for ``--help`` and for errors. ``detect(path)``: whether ``path`` is
    of this source (cheap; never raises). ``read(path, options)``: its entries, in order;
    raises ``ValueError`` with a fix when ``path`` is not readable as this source.
    ``options_type``: the frozen dataclass ``read`` takes. ``choices()``: the names this
    source takes instead of paths (the presets), ``None`` for paths.
    """

    name: str
    flag: str
    help: str
    detect: Callable[[str | Path], bool]
    read: Callable[[str | Path, Any], tuple[Entry, ...]]
    options_type: type = NoOptions
    choices: Callable[[], tuple[str, ...]] | None = None


def pick_source(sources: Sequence[Source], path: str | Path) -> Source:
    """The first of ``sources`` that detects ``path``.

    Raises
    ------
    ValueError
        None does; the message lists what each takes.
    """
    for source in sources:
        if source.detect(path):
            return source
    one_flag = len({s.flag for s in sources}) == 1
    expected = "; or ".join(s.help if one_flag else f"{s.help} ({s.flag})" for s in sources)
    raise ValueError(f"{path} holds nothing these sources read: expected {expected}")


def write_scenes(entries: Sequence[SceneEntry], out_root: str | Path, *,
                 overwrite: bool = False, progress: bool = True) -> list[Path]:
    """Write every scene entry into ``out_root / entry.name``; return the scene folders.

    Each scene is written into a temporary sibling and renamed when finished
    (:func:`envelope.atomic.atomic_directory`), so a folder with the final name is
    always complete. An existing scene is kept unless ``overwrite``.
    """
    out_root = Path(out_root)
    folders = []
    for entry in tqdm(entries, desc="scenes", unit="scene", disable=not progress):
        final = out_root / entry.name
        if overwrite or not final.exists():
            with atomic_directory(final) as tmp:
                entry.write(tmp)
        folders.append(final)
    return folders
