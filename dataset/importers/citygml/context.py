"""A CityGML building's surroundings: the other buildings of its city model nearby.

**Which.** The files whose bounding box (x/y, file CRS) comes within
:data:`CONTEXT_RADIUS_M` of the building's file's (:func:`files_near`), and in them every
building but the measured one (the other buildings of its own file included). A
``--citygml`` folder is one city model; a single file is a city model of its own buildings.

**What they are for.** Two things, neither of which changes an area of the truth:

- *occluders*: each becomes a :class:`envelope.neighbours.Neighbour` (its surfaces in
  the measured building's world frame, with their classes and looks), which
  ``python -m dataset.generate --context`` renders in every view;
- *party walls*: a wall of the measured building that a neighbour's wall covers
  (:func:`party_wall_area_m2`) is shared; the building type's rule reads that area
  (:mod:`dataset.importers.citygml.type`).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
import shapely

from dataset.importers.citygml.appearance import face_appearance
from dataset.importers.citygml.buildings import (
    LABEL_OF_KIND,
    benchmark_buildings,
    building_surfaces,
)
from dataset.importers.citygml.facades import Surface
from dataset.importers.citygml.files import CityGmlError
from dataset.importers.citygml.read import CityBuilding, CityModel, read_citygml
from envelope.classes import NO_FACADE, SemanticClass
from envelope.mesh import LabelledMesh
from envelope.neighbours import Neighbour

CONTEXT_RADIUS_M = 30.0
"""Files whose bounding box comes this close to the building's are its neighbourhood: a
street's width and the pavements on both sides, where the cameras of its facade views
stand; what lies further away is behind those cameras."""
PARTY_ANGLE_DEG = 5.0
"""Two walls face each other (a party wall) when their normals are opposite within this."""
PARTY_GAP_M = 0.2
"""... and their planes are this close: the gap modellers leave between two houses' walls."""


@dataclass(frozen=True)
class CityFile:
    """A CityGML file and the x/y bounding box of its polygons (file CRS, metres):
    ``(x_min, y_min, x_max, y_max)``."""

    path: Path
    bbox_m: tuple[float, float, float, float]


def file_bbox_m(model: CityModel) -> tuple[float, float, float, float]:
    """x/y bounding box of every polygon of ``model`` (file CRS, metres)."""
    pts = np.concatenate([r[:, :2] for b in model.buildings for p in b.polygons
                          for r in p.rings_m])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    return (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))


def files_near(bbox_m: Sequence[float], files: Sequence[CityFile],
               radius_m: float = CONTEXT_RADIUS_M) -> tuple[Path, ...]:
    """The files of ``files`` whose bounding box comes within ``radius_m`` of ``bbox_m``
    (the file of ``bbox_m`` itself included), in the given order."""
    x0, y0, x1, y1 = bbox_m
    out = []
    for f in files:
        fx0, fy0, fx1, fy1 = f.bbox_m
        dx, dy = max(fx0 - x1, x0 - fx1, 0.0), max(fy0 - y1, y0 - fy1, 0.0)
        if np.hypot(dx, dy) <= radius_m:
            out.append(f.path)
    return tuple(out)


def read_neighbours(model: CityModel, name: str, files: Sequence[Path],
                    offset_m: np.ndarray) -> tuple[Neighbour, ...]:
    """Every building of ``files`` (``model``'s own file among them or not) except the scene
    ``name`` of ``model``, moved by ``offset_m`` into the measured building's frame (what
    their import repairs is not the measured building's: not reported).

    Raises
    ------
    CityGmlError
        A file is not readable CityGML, or is in another CRS than ``model``.
    """
    own = Path(model.path).resolve()
    out = []
    for path in files:
        other = model if Path(path).resolve() == own else _read(Path(path).resolve())
        if other.crs != model.crs:
            raise CityGmlError(f"{path} is in {other.crs}, {model.path} in {model.crs}: the "
                               "files of one city model need one CRS")
        for b in benchmark_buildings(other):
            if other is model and b.gml_id == name:
                continue
            neighbour = _neighbour(other, b, offset_m)
            if neighbour is not None:
                out.append(neighbour)
    return tuple(out)


def party_wall_area_m2(surfaces: Sequence[Surface], neighbours: Sequence[Neighbour]) -> float:
    """Area (m²) of the walls of ``surfaces`` (world frame) that a neighbour's wall covers:
    normals opposite within :data:`PARTY_ANGLE_DEG`, planes within :data:`PARTY_GAP_M`,
    overlap measured in the wall's plane."""
    if not neighbours:
        return 0.0
    tri = np.concatenate([n.mesh.triangles_m[n.mesh.face_label == SemanticClass.WALL]
                          for n in neighbours])
    if len(tri) == 0:
        return 0.0
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(cross, axis=1)
    normals = cross / np.maximum(length, 1e-300)[:, None]
    lo, hi = tri.min(axis=1), tri.max(axis=1)
    cos = np.cos(np.radians(PARTY_ANGLE_DEG))
    area = 0.0
    for s in surfaces:
        if s.kind != "wall" or abs(s.tri.normal[2]) > 0.1:
            continue
        n = s.tri.normal
        pts = s.tri.vertices_m
        near = ((normals @ n < -cos) & (length > 0)
                & np.all(np.abs((tri - s.tri.origin_m) @ n) < PARTY_GAP_M, axis=1)
                & np.all(lo <= pts.max(axis=0) + PARTY_GAP_M, axis=1)
                & np.all(hi >= pts.min(axis=0) - PARTY_GAP_M, axis=1))
        if not near.any():
            continue
        basis = np.stack([np.cross([0.0, 0.0, 1.0], n), [0.0, 0.0, 1.0]])
        wall = shapely.union_all(shapely.polygons(pts[s.tri.faces] @ basis.T))
        other = shapely.union_all(shapely.polygons(tri[near] @ basis.T))
        area += float(wall.intersection(other).area)
    return area


@lru_cache(maxsize=64)
def _read(path: Path) -> CityModel:
    """A neighbour file, read once per process (a preset's buildings share neighbours)."""
    return read_citygml(path)


def _neighbour(model: CityModel, building: CityBuilding, offset_m: np.ndarray
               ) -> Neighbour | None:
    surfaces = [s for s in building_surfaces(building, Counter())
                if LABEL_OF_KIND[s.kind] is not None]
    if not surfaces:
        return None
    vertices, faces, labels, n = [], [], [], 0
    for s in surfaces:
        vertices.append(s.tri.vertices_m + offset_m)
        faces.append(s.tri.faces + n)
        labels.append(np.full(len(s.tri.faces), int(LABEL_OF_KIND[s.kind])))
        n += len(s.tri.vertices_m)
    mesh = LabelledMesh(np.concatenate(vertices), np.concatenate(faces),
                        np.concatenate(labels), np.full(sum(len(f) for f in faces), NO_FACADE))
    by_id = {p.polygon_id: p for p in building.polygons}
    polys = [by_id[s.polygon_id] for s in surfaces]
    appearance = face_appearance(
        [model.looks.get(p.polygon_id) for p in polys], [(p.ring_ids, p.rings_m) for p in polys],
        [p.reversed for p in polys], [len(s.tri.faces) for s in surfaces], offset_m,
        Path(model.path).parent, Counter())
    return Neighbour(name=f"{Path(model.path).name}#{building.gml_id}", mesh=mesh,
                     appearance=appearance)
