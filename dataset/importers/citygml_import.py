"""CityGML LoD3 buildings -> :class:`dataset.core.truth.Building` (mesh + exact truth), one per
``Building`` / ``BuildingPart`` (docs/importing.md, section "CityGML").

Stages: read the file (:mod:`dataset.importers.citygml_read`); triangulate every polygon
with its holes (:mod:`dataset.importers.citygml_polygons`); put the lowest ground-surface
point at z = 0 and the ground surface's x/y centre at the origin; check the surfaces face
out; find the facades and measure them in their planes
(:mod:`dataset.importers.citygml_facades`); mark which facades the data covers; assemble the
labelled mesh; take the footprint from the ground surface.

**Inside and outside.** Boundary surfaces are not closed solids, so no inside test decides
anything here: every ``WallSurface`` is an outer wall by definition, and its outward side
is its rings' orientation (counter-clockwise seen from outside). A building whose wall,
roof and ground surfaces enclose a negative volume was written the other way round: all
its surfaces are flipped, with a warning.

**Covered facades.** The models come from street-side laser scans: what the scanner did
not see has no windows modelled. A facade is *covered* when at least one window or door
is modelled on it; only covered facades get facade ids, views and truth (the building's
areas and WWR are sums over them). The others (backyard walls, party walls) stay in the
mesh as wall without a facade id and are listed in ``extra["uncovered_facades"]``. The
``dataAvailable`` attribute (Sufficient / NotSufficient) is recorded, not used.

**Orientation.** ``extra["facades"][id]["azimuth_deg"]``: the outward normal's azimuth,
degrees clockwise from the CRS's grid north (+y; for EPSG:32632 UTM grid north, within
about 1 degree of true north in Ingolstadt).
"""

from __future__ import annotations

import re
from collections import Counter
from dataclasses import asdict, replace
from pathlib import Path

import numpy as np
import shapely
from shapely.geometry import Polygon

from dataset.core.classes import NO_FACADE, SemanticClass
from dataset.core.footprint import polygon_to_geojson
from dataset.core.mesh import LabelledMesh
from dataset.core.truth import Building, BuildingTruth, FacadeTruth
from dataset.core.wwr import gross_facade_area_m2, wwr_from_areas
from dataset.importers.citygml_config import CityGmlConfig
from dataset.importers.citygml_facades import FacadeRegions, Surface, building_facades
from dataset.importers.citygml_polygons import triangulate_polygon
from dataset.importers.citygml_read import (
    CityBuilding,
    CityGmlError,
    CityModel,
    citygml_stem,
    read_citygml,
)

_SAFE = re.compile(r"[^A-Za-z0-9_.-]")
LABEL_OF_KIND: dict[str, SemanticClass | None] = {
    "wall": SemanticClass.WALL,
    "roof": SemanticClass.ROOF,
    "window": SemanticClass.WINDOW,
    "door": SemanticClass.DOOR,
    "installation": SemanticClass.OTHER,
    "ground": SemanticClass.OTHER,
    "outer_floor": SemanticClass.OTHER,
    "outer_ceiling": SemanticClass.OTHER,
    "closure": None,  # virtual surfaces close open parts of a model: nothing to see
    "interior": None,  # LoD4 rooms: never seen from outside
}
"""Class of each surface kind in the mesh; None: left out of the mesh."""
WALL_SECTION_M = 0.3
"""Without a ground surface the footprint is what the walls enclose this high above the
lowest wall point: above a street's slope (up to ~0.2 m across a house here), below most
sills (higher, the gaps modellers leave around windows break the outline)."""
_ENCLOSING = ("wall", "roof", "ground", "closure", "outer_floor", "outer_ceiling")


def import_citygml(path: str | Path, *, config: CityGmlConfig | None = None
                   ) -> list[Building]:
    """Every building of a CityGML 2.0/3.0 file with ground truth (one per ``Building`` and
    ``BuildingPart``; a ``Building`` whose geometry is all in its parts gives none itself).

    Raises
    ------
    CityGmlError (a ValueError)
        As :func:`dataset.importers.citygml_read.read_citygml`, or a building with no wall
        surface (named by its ``gml:id``).
    """
    config = CityGmlConfig() if config is None else config
    return [building_from_citygml(model, b, config=config)
            for model in [read_citygml(path)] for b in benchmark_buildings(model)]


def import_citygml_building(path: str | Path, name: str, *,
                            config: CityGmlConfig | None = None) -> Building:
    """The building of ``path`` whose scene name is ``name`` (:func:`benchmark_buildings`):
    what a resumable run re-imports in a worker for one scene.

    Raises
    ------
    CityGmlError
        As :func:`import_citygml`, or no building of that name in the file.
    """
    config = CityGmlConfig() if config is None else config
    model = read_citygml(path)
    for b in benchmark_buildings(model):
        if b.gml_id == name:
            return building_from_citygml(model, b, config=config)
    raise CityGmlError(f"{path} holds no building {name!r}")


def benchmark_buildings(model: CityModel) -> list[CityBuilding]:
    """The buildings of ``model`` that become scenes, their ids made scene names.

    A ``BuildingPart`` without a wall (a stair, a canopy written as a part) joins its
    building as what it is (installations stay "other"), with a warning; a ``Building``
    whose polygons are all in its parts gives no scene itself. A file with one building
    names it after the file (``4018259.xml`` -> ``4018259``); otherwise the ``gml:id``
    (characters other than letters, digits, ``_.-`` become ``_``) names it.
    """
    by_id = {b.gml_id: b for b in model.buildings}
    joined: dict[str, list[CityBuilding]] = {}
    kept = []
    for b in model.buildings:
        has_wall = any(p.kind == "wall" for p in b.polygons)
        if b.is_part and not has_wall and b.parent_id in by_id:
            joined.setdefault(b.parent_id, []).append(b)
        elif b.polygons or not b.is_part and not any(
                c.parent_id == b.gml_id for c in model.buildings):
            kept.append(b)
    out = []
    for b in kept:
        parts = joined.get(b.gml_id, [])
        name = _SAFE.sub("_", citygml_stem(model.path) if len(kept) == 1 else b.gml_id)
        out.append(replace(
            b, gml_id=name if name[:1].isalnum() else f"b{name}",
            polygons=b.polygons + tuple(p for c in parts for p in c.polygons),
            attributes={**b.attributes, "gml:id": b.gml_id},
            warnings=b.warnings + tuple(f"part {c.gml_id}: no WallSurface, joined to its "
                                        "building" for c in parts)))
    return out


def building_from_citygml(model: CityModel, building: CityBuilding, *,
                          config: CityGmlConfig | None = None) -> Building:
    """One building's labelled mesh and truth (ids of the facades the data covers, from 1).

    Raises
    ------
    CityGmlError
        The building has no (non-degenerate) ``WallSurface`` polygon.
    """
    config = CityGmlConfig() if config is None else config
    where = f"{model.path}: building {building.attributes.get('gml:id', building.gml_id)}"
    warnings: Counter[str] = Counter(_warning_kind(w) for w in building.warnings)
    surfaces = []
    for p in building.polygons:
        tri = triangulate_polygon(p.rings_m)
        if tri is None:
            warnings["polygon without area dropped"] += 1
            continue
        warnings["non-planar polygon (> 1 cm), triangulated as it stands"] += tri.non_planar
        warnings["self-intersecting polygon, made valid"] += tri.repaired
        surfaces.append(Surface(p.polygon_id, p.kind, p.owner_id, p.rings_m, tri))
    if not any(s.kind == "wall" for s in surfaces):
        raise CityGmlError(f"{where} has no WallSurface polygon with an area; a benchmark "
                           "building needs its walls (LoD2 or LoD3 boundary surfaces)")
    offset, ground_z = _offset(surfaces, config, warnings)
    surfaces = [_moved(s, offset) for s in surfaces]
    if _enclosed_volume_m3(surfaces) < 0:
        surfaces = [_flipped(s) for s in surfaces]
        warnings["surfaces faced inwards (negative enclosed volume): all flipped"] += 1
    facades, opening_facade = building_facades(surfaces, config)
    covered = [k for k, f in enumerate(facades) if f.window.area + f.door.area > 0]
    facade_id = {k: i + 1 for i, k in enumerate(covered)}
    mesh = _mesh(surfaces, facades, opening_facade, facade_id)
    truths = tuple(_facade_truth(facade_id[k], facades[k]) for k in covered)
    window, wall, door = (sum(getattr(f, a) for f in truths)
                          for a in ("window_area_m2", "wall_area_m2", "door_area_m2"))
    footprint = _footprint(surfaces, mesh, warnings, where)
    height = float(mesh.vertices_m[:, 2].max())
    truth = BuildingTruth(
        id=building.gml_id, type="imported",
        floors=max(1, round(height / config.floor_height_m)), height_m=height,
        window_area_m2=window, facade_area_m2=gross_facade_area_m2(wall, window, door),
        wall_area_m2=wall, door_area_m2=door, wwr=wwr_from_areas(window, wall, door),
        footprint=polygon_to_geojson(footprint), footprint_area_m2=float(footprint.area),
        facades=truths, name=f"{model.path.name}#{building.gml_id}",
        facade_outlines_m={facade_id[k]: (tuple(map(tuple, facades[k].outline_m())),)
                           for k in covered},
        extra={
            "source_file": model.path.name,
            "citygml_version": model.version,
            "crs": model.crs,
            "offset_m": [float(x) for x in offset],
            "ground_z_m": ground_z,
            "gml_id": building.attributes.get("gml:id", building.gml_id),
            "attributes": dict(sorted((k, v) for k, v in building.attributes.items()
                                      if k != "gml:id")),
            "data_available": building.attributes.get("dataAvailable", ""),
            "facades": {str(facade_id[k]): _facade_record(facades[k], surfaces)
                        for k in covered},
            "uncovered_facades": [_uncovered_record(f, surfaces) for k, f in enumerate(facades)
                                  if k not in facade_id],
            "unassigned_openings": sorted(o for o in {s.owner_id for s in surfaces
                                                      if s.kind in ("window", "door")}
                                          if o not in opening_facade),
            "opening_fill_area_m2": float(sum(_fill_area(facades[k]) for k in covered)),
            "counts": dict(sorted(Counter(s.kind for s in surfaces).items())),
            "warnings": dict(sorted((k, v) for k, v in warnings.items() if v)),
            "import_config": asdict(config),
        },
    )
    return Building(mesh=mesh, truth=truth)


def azimuth_deg(normal: np.ndarray) -> float:
    """Azimuth of a horizontal direction, degrees clockwise from +y (grid north), in [0, 360)."""
    return float(np.degrees(np.arctan2(normal[0], normal[1])) % 360.0)


def _warning_kind(message: str) -> str:
    return message.split(": ", 1)[-1]


def _offset(surfaces: list[Surface], config: CityGmlConfig, warnings: Counter
            ) -> tuple[np.ndarray, float]:
    """The shift (3,) that puts the lowest ground-surface point at z = 0 and the ground
    surface's x/y bounding-box centre at the origin (walls without a ground surface)."""
    ground = [s.tri.vertices_m for s in surfaces if s.kind == "ground"]
    if not ground:
        warnings["no GroundSurface: ground at the lowest wall point"] += 1
        ground = [s.tri.vertices_m for s in surfaces if s.kind == "wall"]
    pts = np.concatenate(ground)
    ground_z = float(pts[:, 2].min())
    if not config.recentre:
        return np.array([0.0, 0.0, -ground_z]), ground_z
    lo, hi = pts[:, :2].min(axis=0), pts[:, :2].max(axis=0)
    return -np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, ground_z]), ground_z


def _moved(s: Surface, offset: np.ndarray) -> Surface:
    t = s.tri
    tri = replace(t, vertices_m=t.vertices_m + offset, origin_m=t.origin_m + offset)
    return replace(s, rings_m=tuple(r + offset for r in s.rings_m), tri=tri)


def _flipped(s: Surface) -> Surface:
    t = s.tri
    tri = replace(t, faces=t.faces[:, ::-1].copy(), normal=-t.normal)
    return replace(s, rings_m=tuple(r[::-1] for r in s.rings_m), tri=tri)


def _enclosed_volume_m3(surfaces: list[Surface]) -> float:
    """Signed volume of the enclosing surfaces' triangles (divergence theorem)."""
    t = np.concatenate([s.tri.vertices_m[s.tri.faces] for s in surfaces
                        if s.kind in _ENCLOSING])
    return float(np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6.0)


def _mesh(surfaces: list[Surface], facades: list[FacadeRegions], opening_facade: dict,
          facade_id: dict[int, int]) -> LabelledMesh:
    wall_facade = {i: facade_id[k] for k, f in enumerate(facades) if k in facade_id
                   for i in f.surfaces}
    vertices, faces, labels, fids = [], [], [], []
    n = 0
    for i, s in enumerate(surfaces):
        label = LABEL_OF_KIND[s.kind]
        if label is None:
            continue
        fid = (wall_facade.get(i, NO_FACADE) if s.kind == "wall" else
               facade_id.get(opening_facade.get(s.owner_id, -1), NO_FACADE)
               if s.kind in ("window", "door") else NO_FACADE)
        vertices.append(s.tri.vertices_m)
        faces.append(s.tri.faces + n)
        labels.append(np.full(len(s.tri.faces), int(label)))
        fids.append(np.full(len(s.tri.faces), fid))
        n += len(s.tri.vertices_m)
    for k, fid in facade_id.items():
        fill = facades[k].fill_m
        if len(fill):
            vertices.append(fill.reshape(-1, 3))
            faces.append(np.arange(len(fill) * 3).reshape(-1, 3) + n)
            labels.append(np.array([int(LABEL_OF_KIND[c]) for c in facades[k].fill_kind]))
            fids.append(np.full(len(fill), fid))
            n += len(fill) * 3
    return LabelledMesh(np.concatenate(vertices), np.concatenate(faces),
                        np.concatenate(labels), np.concatenate(fids))


def _facade_truth(fid: int, f: FacadeRegions) -> FacadeTruth:
    window, door, wall = float(f.window.area), float(f.door.area), float(f.wall.area)
    u0, v0, u1, v1 = f.gross.bounds
    return FacadeTruth(
        id=fid, normal=tuple(float(x) for x in f.normal), width_m=float(u1 - u0),
        height_m=float(v1 - v0), window_area_m2=window, wall_area_m2=wall, door_area_m2=door,
        facade_area_m2=gross_facade_area_m2(wall, window, door),
        wwr=wwr_from_areas(window, wall, door))


def _facade_record(f: FacadeRegions, surfaces: list[Surface]) -> dict:
    """Identity and orientation of a covered facade (its wall polygons and openings)."""
    return {"azimuth_deg": azimuth_deg(f.normal),
            "wall_polygon_ids": [surfaces[i].polygon_id for i in f.surfaces],
            "opening_ids": list(f.openings)}


def _uncovered_record(f: FacadeRegions, surfaces: list[Surface]) -> dict:
    return {"azimuth_deg": azimuth_deg(f.normal), "normal": [float(x) for x in f.normal],
            "wall_area_m2": float(f.wall.area), "width_m": float(f.gross.bounds[2]
                                                                  - f.gross.bounds[0]),
            "wall_polygon_ids": [surfaces[i].polygon_id for i in f.surfaces]}


def _fill_area(f: FacadeRegions) -> float:
    t = f.fill_m
    return float(0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]),
                                      axis=1).sum()) if len(t) else 0.0


def _footprint(surfaces: list[Surface], mesh: LabelledMesh, warnings: Counter, where: str):
    """Union of the ground surfaces seen from above; without one, what the walls enclose
    :data:`WALL_SECTION_M` above the lowest wall point (:func:`_walls_outline`)."""
    ground = [Polygon(r[0][:, :2], [h[:, :2] for h in r[1:]])
              for r in (s.rings_m for s in surfaces if s.kind == "ground")]
    if ground:
        return shapely.union_all([g if g.is_valid else shapely.make_valid(g) for g in ground])
    warnings[f"footprint from the walls {WALL_SECTION_M} m above the ground (no "
             "GroundSurface)"] += 1
    outline = _walls_outline(mesh, WALL_SECTION_M)
    if outline.is_empty:
        raise CityGmlError(f"{where}: no GroundSurface, and the walls {WALL_SECTION_M} m above "
                           "the ground enclose nothing; add the GroundSurface")
    return outline


def _walls_outline(mesh: LabelledMesh, z_m: float):
    """The region the wall, window and door faces enclose at height ``z_m``: their section's
    segments polygonised, every face of that arrangement kept, holes filled. Boundary
    surfaces are open (no floor), so the mesh's inside rule cannot decide here."""
    import trimesh
    from shapely.geometry import MultiLineString
    from shapely.ops import polygonize

    facing = np.isin(mesh.face_label, [int(SemanticClass.WALL), int(SemanticClass.WINDOW),
                                       int(SemanticClass.DOOR)])
    tm = trimesh.Trimesh(mesh.vertices_m, mesh.faces[facing], process=False)
    segments = trimesh.intersections.mesh_plane(tm, [0.0, 0.0, 1.0], [0.0, 0.0, z_m])
    if len(segments) == 0:
        return Polygon()
    lines = shapely.set_precision(MultiLineString([s[:, :2] for s in segments]), 1e-6)
    regions = shapely.union_all([p for p in polygonize(shapely.union_all(lines))
                                 if p.area > 0])
    parts = getattr(regions, "geoms", [regions])
    return shapely.union_all([Polygon(p.exterior) for p in parts if not p.is_empty])
