"""The city model a photos scene is fitted to (``--city-model FILE_OR_DIR``, with
``--city-building ID``): one building of a CityGML model and the buildings around it, as the
triangles of their visible surfaces in that building's frame (docs/importing.md, section 9).

Read with the CityGML importer's own reader (:mod:`dataset.importers.citygml`, lxml): the
files given are one city model, as with ``--citygml``; the building's neighbours are every
building of the files whose x/y bounding box comes within
:data:`~dataset.importers.citygml.context.CONTEXT_RADIUS_M` of its file's
(:func:`~dataset.importers.citygml.context.files_near`, the other buildings of its own file
among them).

**Which surfaces**: every polygon a camera can see from outside (:data:`FIT_KINDS`: walls,
roofs, and in LoD3 the windows, doors, installations, balconies), not the ground surface
(under the building) nor closure surfaces (virtual).

**Frame**: the building's, as ``--citygml`` imports it
(:func:`~dataset.importers.citygml.convert.recentre_offset`): ``frame = CRS + offset_m``,
the ground surface's x/y bounding-box centre at the origin and its lowest point at z = 0;
+y is the CRS's grid north, which lies ``north_deg`` clockwise of true north (the meridian
convergence, :func:`~dataset.importers.citygml.grid_north.grid_north_deg`).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from dataset.importers.citygml.buildings import benchmark_buildings, building_surfaces
from dataset.importers.citygml.config import CityGmlConfig
from dataset.importers.citygml.context import CityFile, file_bbox_m, files_near
from dataset.importers.citygml.convert import recentre_offset
from dataset.importers.citygml.files import CityGmlError, citygml_files
from dataset.importers.citygml.grid_north import grid_north_deg
from dataset.importers.citygml.read import CityBuilding, read_citygml

FIT_KINDS = frozenset({"wall", "roof", "window", "door", "installation", "outer_floor",
                       "outer_ceiling"})
"""Surface kinds (:data:`dataset.importers.citygml.read.SURFACE_KINDS`) the photos' points
are fitted to: what is seen from outside."""


@dataclass(frozen=True)
class CityTarget:
    """The surfaces the points are fitted to.

    ``triangles_m``: (T, 3, 3) every visible triangle of the building and its neighbours,
    in the building's frame (metres); ``building_triangles``: how many of them, first, are
    the building's own; ``offset_m``: (3,) ``frame = CRS + offset_m``; ``north_deg``: true
    north to the frame's +y, clockwise (degrees); ``neighbours``: the other buildings'
    names (``<file>#<id>``).
    """

    triangles_m: np.ndarray
    building_triangles: int
    building: str
    files: tuple[Path, ...]
    neighbours: tuple[str, ...]
    crs: str
    offset_m: np.ndarray
    north_deg: float

    @property
    def building_height_m(self) -> float:
        """The building's top above its lowest ground point (m)."""
        return float(self.triangles_m[:self.building_triangles, :, 2].max())

    def record(self) -> dict:
        """What the scene's ``photos`` record says of the city model."""
        return {"files": [str(f) for f in self.files], "building": self.building,
                "neighbours": len(self.neighbours), "crs": self.crs,
                "offset_m": [round(float(x), 4) for x in self.offset_m],
                "triangles": len(self.triangles_m)}


def read_city_target(path: str | Path, building_id: str | None = None) -> CityTarget:
    """The city model at ``path`` (a CityGML file or a folder of them: one city model) and
    its building ``building_id`` (the scene name ``--citygml`` gives it, or its
    ``gml:id`` where no scene has that name and one building that id; ``None``: the
    model's only building).

    Raises
    ------
    CityGmlError (a ValueError)
        A file that is not readable CityGML (as
        :func:`~dataset.importers.citygml.read.read_citygml`), no building of that id, no id
        given for a model of several buildings, a gml:id that several buildings share, or a
        building without a wall.
    """
    files = citygml_files(path)
    models = [read_citygml(f) for f in files]
    buildings = [(i, b) for i, m in enumerate(models) for b in benchmark_buildings(m)]
    chosen = _chosen(path, buildings, building_id)
    index, building = buildings[chosen]
    model = models[index]
    surfaces = building_surfaces(building, Counter())
    if not any(s.kind == "wall" for s in surfaces):
        raise CityGmlError(f"{files[index]}: building {building.gml_id} has no WallSurface "
                           "with an area; the photos are fitted to walls: choose another "
                           "building with --city-building")
    offset, _, centre_xy = recentre_offset(surfaces, CityGmlConfig(), Counter())
    own = _triangles(building)
    city = [CityFile(f, file_bbox_m(m)) for f, m in zip(files, models)]
    near = set(files_near(city[index].bbox_m, city))
    others = [(files[i], b) for n, (i, b) in enumerate(buildings)
              if n != chosen and files[i] in near]
    for f, _ in others:
        if models[files.index(f)].crs != model.crs:
            raise CityGmlError(f"{f} is in {models[files.index(f)].crs}, {files[index]} in "
                               f"{model.crs}: the files of one city model need one CRS")
    triangles = [own] + [_triangles(b) for _, b in others]
    return CityTarget(np.concatenate(triangles) + offset, len(own), building.gml_id,
                      tuple(files), tuple(f"{f.name}#{b.gml_id}" for f, b in others),
                      model.crs, offset, grid_north_deg(model.crs, *centre_xy))


def _chosen(path: str | Path, buildings: list[tuple[int, CityBuilding]],
            building_id: str | None) -> int:
    names = [b.gml_id for _, b in buildings]
    if building_id is None:
        if len(buildings) == 1:
            return 0
        raise CityGmlError(
            f"{path} holds {len(buildings)} buildings: say which one the photos show with "
            f"--city-building ID (e.g. {', '.join(names[:5])}{' ...' if len(names) > 5 else ''})")
    if names.count(building_id) == 1:
        return names.index(building_id)
    by_gml = [n for n, (_, b) in enumerate(buildings) if b.attributes.get("gml:id") == building_id]
    if len(by_gml) == 1:
        return by_gml[0]
    if len(by_gml) > 1:  # files of one city model that repeat a gml:id
        raise CityGmlError(f"{path}: {len(by_gml)} buildings have the gml:id {building_id!r}: "
                           f"give the scene name instead, one of "
                           f"{', '.join(names[n] for n in by_gml)}")
    raise CityGmlError(f"{path} holds no building {building_id!r} (its buildings: "
                       f"{', '.join(names[:8])}{' ...' if len(names) > 8 else ''})")


def _triangles(building: CityBuilding) -> np.ndarray:
    """(T, 3, 3) the building's visible triangles (file CRS)."""
    tris = [s.tri.vertices_m[s.tri.faces] for s in building_surfaces(building, Counter())
            if s.kind in FIT_KINDS]
    return np.concatenate(tris) if tris else np.zeros((0, 3, 3))
