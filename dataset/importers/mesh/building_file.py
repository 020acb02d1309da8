"""A building file as a source: a labelled mesh (:data:`MESH_SOURCE`) or an IFC model
(:data:`IFC_SOURCE`), one building each, rendered by ``python -m dataset.generate``.

Reading the source only checks the file and fingerprints it; the import itself
(:func:`dataset.importers.mesh.mesh_import.import_labelled_mesh`,
:func:`dataset.importers.ifc.convert.import_ifc`) runs when the scene has to be rendered,
so a rerun skips a finished scene without importing again. The scene's provenance records
the file's fingerprint, the import options and, for IFC, the class overrides' fingerprint.
"""

from __future__ import annotations

import sys
from dataclasses import asdict, dataclass, field
from functools import partial
from pathlib import Path
from typing import Any

from dataset.importers.import_config import ImportConfig
from dataset.importers.source import BuildingEntry, Source
from envelope.provenance import file_fingerprint
from envelope.truth import Building

MESH_SUFFIXES = (".ply", ".obj", ".glb", ".gltf")
IFC_SUFFIXES = (".ifc",)


@dataclass(frozen=True)
class BuildingFileOptions:
    """How a building file becomes a building."""

    config: ImportConfig = field(default_factory=ImportConfig)
    """Ground, placement, grouping and visibility options (docs/importing.md)."""
    building_id: str | None = None
    """The truth's id and the scene folder's name; ``None``: the file name without suffix."""
    ifc_classes: Path | None = None
    """IFC only: a JSON file mapping IFC entities or GlobalIds to classes
    (:func:`dataset.importers.ifc.classes.read_class_overrides`)."""
    progress: bool = True
    """Show IfcOpenShell's progress bar (not part of the scene's provenance)."""


def read_mesh_file(path: str | Path, options: BuildingFileOptions) -> tuple[BuildingEntry]:
    """The labelled mesh at ``path`` as one building entry (import deferred, module docstring).

    Raises
    ------
    ValueError
        The file is missing, or ``options`` name IFC class overrides.
    """
    path = _existing_file(path)
    if options.ifc_classes is not None:
        raise ValueError(f"{path} is a mesh: IFC class overrides (--ifc-classes) apply to "
                         "IFC models only")
    name = options.building_id or path.stem
    return (BuildingEntry(name, partial(_import_mesh, path, name, options.config),
                          file_inputs(path, options)),)


def read_ifc_file(path: str | Path, options: BuildingFileOptions) -> tuple[BuildingEntry]:
    """The IFC model at ``path`` as one building entry (import deferred, module docstring).

    Raises
    ------
    ValueError
        The model or the class overrides file is missing.
    """
    path = _existing_file(path)
    if options.ifc_classes is not None:
        _existing_file(options.ifc_classes)
    name = options.building_id or path.stem
    return (BuildingEntry(name, partial(_import_ifc, path, name, options),
                          file_inputs(path, options)),)


def file_inputs(path: Path, options: BuildingFileOptions) -> dict[str, Any]:
    """What a scene imported from ``path`` is made from, for its provenance record: the
    fingerprints of the file (and of the class overrides) and the import options."""
    inputs: dict[str, Any] = {"source": file_fingerprint(path), "import": asdict(options.config)}
    if options.ifc_classes is not None:
        inputs["classes"] = file_fingerprint(options.ifc_classes)
    return inputs


def _existing_file(path: str | Path) -> Path:
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path} does not exist or is not a file")
    return path


def _import_mesh(path: Path, name: str, config: ImportConfig) -> Building:
    from dataset.importers.mesh.mesh_import import import_labelled_mesh

    return import_labelled_mesh(path, building_id=name, config=config)


def _import_ifc(path: Path, name: str, options: BuildingFileOptions) -> Building:
    """Import the IFC model; its warnings go to stderr, one line per kind with its count."""
    from dataset.importers.ifc.classes import read_class_overrides
    from dataset.importers.ifc.convert import import_ifc, warning_lines

    overrides = (None if options.ifc_classes is None
                 else read_class_overrides(options.ifc_classes))
    building = import_ifc(path, building_id=name, config=options.config, overrides=overrides,
                          progress=options.progress)
    for line in warning_lines(building.truth.extra["ifc"]):
        print(line, file=sys.stderr)
    return building


def _has_suffix(path: str | Path, suffixes: tuple[str, ...]) -> bool:
    return Path(path).suffix.lower() in suffixes and Path(path).is_file()


MESH_SOURCE = Source(
    name="mesh", flag="--mesh",
    help="your labelled mesh (.ply with per-face label, or .obj/.glb/.gltf with class-named "
         "parts), metres, z up; see docs/importing.md",
    detect=partial(_has_suffix, suffixes=MESH_SUFFIXES), read=read_mesh_file,
    options_type=BuildingFileOptions,
)
IFC_SOURCE = Source(
    name="ifc", flag="--ifc",
    help="an IFC model (ArchiCAD, Revit, ... export); see docs/importing.md",
    detect=partial(_has_suffix, suffixes=IFC_SUFFIXES), read=read_ifc_file,
    options_type=BuildingFileOptions,
)
