"""The sources on the command line: their options, and the typed options each source reads,
built from the parsed arguments once.

Shared by ``python -m dataset.generate`` and ``python -m dataset.importer``. Each flag of
:data:`dataset.sources.SOURCES` becomes an option (sources that share a flag are told apart
by their ``detect``), ``--input PATH`` takes the first source that detects PATH, and every
field of :class:`dataset.importers.import_config.ImportConfig` is an option with its default
(``--ground-z``, ``--footprint-height-m``, ...). Nothing below this module sees an
``argparse.Namespace``: :func:`source_options` turns the arguments into the source's frozen
options dataclass.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from dataclasses import fields
from pathlib import Path
from typing import Any

from dataset.importers.import_config import ImportConfig
from dataset.importers.mesh.building_file import BuildingFileOptions
from dataset.importers.photos.gps_fit import MIN_FIXES, MIN_SPREAD_M
from dataset.importers.photos.metric_frame import KnownDistance, ScaleHint
from dataset.importers.photos.source import PhotosOptions
from dataset.importers.source import NoOptions, Source, pick_source

_IMPORT_HELP = {
    "up_axis": "the file's up axis; glTF from Blender is y",
    "ground_z_m": "ground level in the file (metres, after --up-axis): what lies below is "
                  "underground, never facade (default: the lowest point; IFC: the storey at "
                  "grade, docs/importing.md)",
    "max_tilt_deg": "faces tilted further than this from upright are no facade",
    "angle_tolerance_deg": "faces within this angle of a facade's direction join it",
    "offset_tolerance_m": "parallel planes closer than this are one facade",
    "gap_tolerance_m": "coplanar wall pieces further apart than this are two facades",
    "min_facade_width_m": "narrower face groups (reveals) belong to no facade",
    "rays_per_sample": "visibility rays per sample point (4 points per face)",
    "min_escape_fraction": "a face is seen from outside if this share of its rays escape",
    "ray_offset_m": "rays start this far off the surface",
    "footprint_height_m": "footprint section height above the ground",
    "floor_height_m": "storey height for the floor count",
}
_IMPORT_FLAGS = {"ground_z_m": "--ground-z"}


def add_source_arguments(group: argparse._ActionsContainer, sources: Sequence[Source]) -> None:
    """One option per flag of ``sources``, and ``--input``, into ``group`` (a required
    mutually exclusive group: exactly one source per run)."""
    for flag, same in _by_flag(sources).items():
        choices = same[0].choices() if same[0].choices is not None else None
        group.add_argument(flag, dest=_dest(flag), choices=choices,
                           metavar=None if choices else "PATH",
                           help="; or ".join(s.help for s in same))
    group.add_argument("--input", metavar="PATH",
                       help="any of these: the first source that recognises PATH (a preset's "
                            "name, a mesh or IFC file by its suffix, an official layout by its "
                            "files)")


def add_import_arguments(parser: argparse.ArgumentParser) -> None:
    """One option per :class:`ImportConfig` field (``recentre`` becomes ``--keep-position``)
    and ``--ifc-classes``, in a group of their own; the photos source's scale options in
    another."""
    group = parser.add_argument_group("import options, with --mesh or --ifc "
                                      "(docs/importing.md)")
    defaults = ImportConfig()
    for field in fields(ImportConfig):
        if field.name == "recentre":
            group.add_argument("--keep-position", action="store_true",
                               help="keep the file's coordinates instead of centring the "
                               "building on the origin with its ground at z = 0")
            continue
        flag = _IMPORT_FLAGS.get(field.name, "--" + field.name.replace("_", "-"))
        default = getattr(defaults, field.name)
        kind = {"up_axis": str, "rays_per_sample": int}.get(field.name, float)
        group.add_argument(flag, dest=f"import_{field.name}", type=kind, default=default,
                           metavar=None if field.name == "up_axis" else "X",
                           choices=("z", "y") if field.name == "up_axis" else None,
                           help=f"{_IMPORT_HELP[field.name]} (default: {default})")
    group.add_argument("--ifc-classes", type=Path, metavar="JSON",
                       help="with --ifc: your entity/GlobalId -> class mapping, e.g. "
                            '{"IfcCovering": "wall", "IfcRailing": "skip"}')
    photos = parser.add_argument_group("photos options, with --photos: one scale is needed "
                                       "(docs/importing.md, section 9)")
    photos.add_argument("--known-distance", nargs=3, metavar=("PHOTO_A", "PHOTO_B", "METRES"),
                        help="the distance in metres between the places two photos (file "
                             "names) were taken from")
    photos.add_argument("--known-height", type=float, metavar="METRES",
                        help="the building's height in metres, ground to top")
    photos.add_argument("--gps", action="store_true",
                        help="the scale and true north from the photos' EXIF GPS positions "
                             f"(at least {MIN_FIXES} photos with a fix, spread {MIN_SPREAD_M:g} m "
                             "or more about their mean; +y becomes north, x east)")
    photos.add_argument("--city-model", type=Path, metavar="FILE_OR_DIR",
                        help="the scale, north and place from a CityGML model (LoD2 or LoD3; "
                             "a file or a folder of them, one city model) of the building the "
                             "photos show and its neighbours: the sparse points are fitted to "
                             "its walls and roofs; the scene lands in the building's frame as "
                             "--citygml imports it, +y the CRS's grid north")
    photos.add_argument("--city-building", metavar="ID",
                        help="with --city-model: the building the photos show (its scene name "
                             "or gml:id), where the model holds several")


def chosen_source(args: argparse.Namespace, sources: Sequence[Source]) -> tuple[Source, str]:
    """The source the arguments name, and the path (or name) given to it.

    Raises
    ------
    ValueError
        No source of the flag (or none at all, for ``--input``) detects the path.
    """
    if args.input is not None:
        return pick_source(sources, args.input), args.input
    for flag, same in _by_flag(sources).items():
        value = getattr(args, _dest(flag))
        if value is not None:
            # One source: its own reader says best what is wrong with a path.
            return (same[0] if len(same) == 1 else pick_source(same, value)), value
    raise ValueError(f"no source given: use one of {', '.join(_by_flag(sources))} or --input")


def source_options(source: Source, args: argparse.Namespace, *, building_id: str | None = None,
                   progress: bool = True) -> Any:
    """The options ``source`` reads, from the arguments of :func:`add_import_arguments`.

    Raises
    ------
    ValueError
        An option out of range, or ``--ifc-classes`` for a source that is no building file.
    """
    if source.options_type is BuildingFileOptions:
        return BuildingFileOptions(import_config_from_args(args), building_id=building_id,
                                   ifc_classes=args.ifc_classes, progress=progress)
    if args.ifc_classes is not None:
        raise ValueError(f"--ifc-classes goes with --ifc, not with {source.flag}")
    scale_given = (args.known_distance is not None or args.known_height is not None
                   or args.gps or args.city_model is not None
                   or args.city_building is not None)
    if source.options_type is PhotosOptions:
        return PhotosOptions(photos_scale_from_args(args) if scale_given else None,
                             progress=progress)
    if scale_given:
        raise ValueError(f"--known-distance, --known-height, --gps and --city-model go with "
                         f"--photos, not with {source.flag}")
    if source.options_type is NoOptions:
        return NoOptions()
    raise ValueError(f"source {source.name} reads {source.options_type.__name__}, which the "
                     "command line cannot build yet: add it to dataset.source_args")


def import_config_from_args(args: argparse.Namespace) -> ImportConfig:
    """The :class:`ImportConfig` that the options of :func:`add_import_arguments` ask for.

    Raises
    ------
    ValueError
        An option out of range.
    """
    values = {f.name: getattr(args, f"import_{f.name}") for f in fields(ImportConfig)
              if f.name != "recentre"}
    return ImportConfig(recentre=not args.keep_position, **values)


def photos_scale_from_args(args: argparse.Namespace) -> ScaleHint:
    """The :class:`ScaleHint` of ``--known-distance`` / ``--known-height`` / ``--gps`` /
    ``--city-model`` (and ``--city-building``).

    Raises
    ------
    ValueError
        A distance that is no number, none or both given, or a value out of range.
    """
    known = None
    if args.known_distance is not None:
        photo_a, photo_b, metres = args.known_distance
        try:
            known = KnownDistance(photo_a, photo_b, float(metres))
        except ValueError:
            raise ValueError(f"--known-distance PHOTO_A PHOTO_B METRES: {metres!r} is not a "
                             "number of metres") from None
    return ScaleHint(known, args.known_height, gps=args.gps, city_model=args.city_model,
                     city_building=args.city_building)


def _by_flag(sources: Sequence[Source]) -> dict[str, list[Source]]:
    by_flag: dict[str, list[Source]] = {}
    for source in sources:
        by_flag.setdefault(source.flag, []).append(source)
    return by_flag


def _dest(flag: str) -> str:
    return flag.lstrip("-").replace("-", "_")
