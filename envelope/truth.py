"""Exact ground truth of one building: ``building.json`` (docs/DESIGN.md).

Areas follow one convention everywhere: a window's (or door's) area is its
opening in the facade plane; the reveal (the shallow recess around it) is not
facade area. Gross facade area = wall + window + door; WWR comes from
:class:`envelope.wwr.ClassAreas`, the project's one definition.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any, Literal

from envelope.appearance import SurfaceAppearance
from envelope.atomic import write_json_atomic
from envelope.mesh import LabelledMesh
from envelope.neighbours import Neighbour, Street
from envelope.orientation import (
    NORTH_SOURCES,
    NorthSource,
    OrientationBin,
    azimuth_deg_from_normal,
    orientation_bin,
)
from envelope.wwr import ClassAreas

BuildingType = Literal["skyscraper", "l_shaped", "realistic", "imported", "with_balconies",
                       "terraced", "detached"]
BUILDING_TYPES: tuple[str, ...] = ("skyscraper", "l_shaped", "realistic", "imported",
                                   "with_balconies", "terraced", "detached")
"""The procedural families, ``imported`` (a mesh or IFC model), and the types CityGML
buildings get from their geometry (:mod:`dataset.importers.citygml.type`)."""
_DERIVED_FACADE_KEYS = ("azimuth_deg", "orientation")


@dataclass(frozen=True)
class FacadeTruth:
    """One facade: a wall plane (or a curved wall) facing one way.

    ``normal`` is the outward unit vector in the world frame (for a curved
    facade, the mean outward direction); ``width_m`` is measured along the wall
    (arc length for a curved one). ``azimuth_deg`` (clockwise from true north,
    :mod:`envelope.orientation`) is derived from ``normal`` and the building's
    ``north_deg`` when the :class:`BuildingTruth` is made (``None``: a vertical normal).
    ``visible_*_area_m2``: the part seen straight on
    from the front, not hidden by a railing, a balcony or an overhang
    (:mod:`dataset.families.visible_facade`); ``None`` where not computed (older files,
    imported meshes).
    """

    id: int
    normal: tuple[float, float, float]
    width_m: float
    height_m: float
    window_area_m2: float
    wall_area_m2: float
    door_area_m2: float
    facade_area_m2: float
    wwr: float
    curved: bool = False
    visible_window_area_m2: float | None = None
    visible_wall_area_m2: float | None = None
    visible_door_area_m2: float | None = None
    azimuth_deg: float | None = None

    @property
    def orientation(self) -> OrientationBin | None:
        """EnergyPlus bin (N, E, S, W) of ``azimuth_deg``; ``None`` without one."""
        return None if self.azimuth_deg is None else orientation_bin(self.azimuth_deg)


@dataclass(frozen=True)
class BuildingTruth:
    """Whole-building ground truth; areas in m², lengths in m, world x/y for the footprint.

    ``facade_outlines_m``: per facade id, the world-frame outline of each of its
    walls, (n, 3) corners in metres counter-clockwise seen from outside (a
    planar facade has one, a faceted curved facade one per facet); empty when
    unknown (e.g. imported meshes). Evaluation matches a method's own facades
    to the truth's by them. Older files kept them in ``extra["facade_outlines_m"]``:
    they are moved here when read (and when built that way).

    ``north_deg``: clockwise angle from true north to world +y (EnergyPlus North
    Axis), stated by the source (``north_source``); procedural scenes keep the
    convention 0 (+y is north). Each facade's ``azimuth_deg`` is derived from it.
    """

    id: str
    type: BuildingType
    floors: int
    height_m: float
    window_area_m2: float
    facade_area_m2: float
    wall_area_m2: float
    door_area_m2: float
    wwr: float
    footprint: dict[str, Any]  # GeoJSON Polygon, world x/y metres
    footprint_area_m2: float
    facades: tuple[FacadeTruth, ...]
    name: str = ""
    seed: int | None = None
    extra: dict[str, Any] = field(default_factory=dict)
    facade_outlines_m: dict[int, tuple[tuple[tuple[float, float, float], ...], ...]] = field(
        default_factory=dict)
    north_deg: float = 0.0
    north_source: NorthSource = "convention"

    def __post_init__(self) -> None:
        outlines = self.facade_outlines_m
        if not outlines and "facade_outlines_m" in self.extra:
            outlines = self.extra["facade_outlines_m"]
            object.__setattr__(self, "extra", {k: v for k, v in self.extra.items()
                                               if k != "facade_outlines_m"})
        object.__setattr__(self, "facade_outlines_m", {
            int(fid): tuple(tuple(tuple(float(x) for x in corner) for corner in outline)
                            for outline in walls)
            for fid, walls in outlines.items()
        })
        if self.north_source not in NORTH_SOURCES:
            raise ValueError(f"north_source must be one of {NORTH_SOURCES}, "
                             f"got {self.north_source!r}")
        object.__setattr__(self, "north_deg", float(self.north_deg))
        object.__setattr__(self, "facades", tuple(
            replace(f, azimuth_deg=azimuth_deg_from_normal(f.normal, self.north_deg))
            for f in self.facades))

    def visible_areas_m2(self) -> ClassAreas | None:
        """Window, wall and door areas seen straight on, summed over facades; ``None``
        unless every facade has them."""
        parts = [(f.visible_window_area_m2, f.visible_wall_area_m2, f.visible_door_area_m2)
                 for f in self.facades]
        if not parts or any(x is None for p in parts for x in p):
            return None
        window, wall, door = (float(sum(p[k] for p in parts)) for k in range(3))
        return ClassAreas(window_m2=window, wall_m2=wall, door_m2=door)

    @property
    def counts_every_wall(self) -> bool:
        """Whether the truth's facades are all of the building's walls (``False``: a CityGML
        model whose uncovered walls, backyard and party walls, are listed apart)."""
        return not self.extra.get("uncovered_facades")

    @property
    def uncovered_outlines_m(self) -> tuple[tuple[tuple[float, float, float], ...], ...]:
        """World-frame outlines, (n, 3) corners in m, of the walls the truth lists apart and
        does not count (``extra["uncovered_facades"]``); empty where it counts every wall.

        Raises
        ------
        ValueError
            If an uncovered wall's record has no outline (a scene written before they were
            kept: regenerate it).
        """
        out = []
        for k, record in enumerate(self.extra.get("uncovered_facades", ())):
            if "outline_m" not in record:
                raise ValueError(
                    f"building {self.id}: uncovered wall {k} has no outline_m (the scene was "
                    "written before uncovered walls kept their outlines); regenerate it with "
                    "`python -m dataset.generate`")
            out.append(tuple(tuple(float(x) for x in corner) for corner in record["outline_m"]))
        return tuple(out)

    def facade(self, facade_id: int) -> FacadeTruth:
        """The facade with id ``facade_id``."""
        for f in self.facades:
            if f.id == facade_id:
                return f
        raise KeyError(f"building {self.id} has no facade {facade_id}")

    def to_json_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["facades"] = [asdict(f) for f in self.facades]
        for f, facade in zip(d["facades"], self.facades):
            f["normal"] = list(f["normal"])
            f["orientation"] = facade.orientation
        d["facade_outlines_m"] = {
            str(fid): [[list(corner) for corner in outline] for outline in walls]
            for fid, walls in sorted(self.facade_outlines_m.items())
        }
        return d

    @staticmethod
    def from_json_dict(d: dict[str, Any]) -> BuildingTruth:
        # azimuth and orientation are derived from the normal and north_deg, never read
        facades = tuple(
            FacadeTruth(**{**{k: v for k, v in f.items() if k not in _DERIVED_FACADE_KEYS},
                           "normal": tuple(float(x) for x in f["normal"])})
            for f in d["facades"]
        )
        return BuildingTruth(**{**d, "facades": facades})


@dataclass(frozen=True)
class Building:
    """A building as the generator (or the importer) makes it: labelled mesh + exact truth.

    Where the source knows them: ``appearance``, the mesh faces' textures and colours
    (:mod:`envelope.appearance`), ``context``, the buildings around it, and ``streets``,
    the lanes of its road network (:mod:`envelope.neighbours`); none changes the truth.
    """

    mesh: LabelledMesh
    truth: BuildingTruth
    appearance: SurfaceAppearance | None = None
    context: tuple[Neighbour, ...] = ()
    streets: tuple[Street, ...] = ()

    def __post_init__(self) -> None:
        if self.appearance is not None and len(self.appearance.face_material) != len(
                self.mesh.faces):
            raise ValueError("a building's appearance needs one entry per face of its mesh")
        object.__setattr__(self, "context", tuple(self.context))
        object.__setattr__(self, "streets", tuple(self.streets))


def write_building(path: str | Path, truth: BuildingTruth) -> None:
    """Write ``building.json`` atomically (deterministic bytes for equal input)."""
    write_json_atomic(path, truth.to_json_dict())


def read_building(path: str | Path) -> BuildingTruth:
    """Read ``building.json``.

    Raises
    ------
    ValueError
        If the file is missing or lacks a field of docs/DESIGN.md's schema.
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"ground truth file {path} does not exist")
    try:
        return BuildingTruth.from_json_dict(json.loads(path.read_text()))
    except (json.JSONDecodeError, TypeError, KeyError) as exc:
        raise ValueError(f"{path} is not a valid building.json: {exc}") from exc
