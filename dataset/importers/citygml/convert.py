"""CityGML LoD3 buildings -> :class:`envelope.truth.Building` (mesh + exact truth), one per
``Building`` / ``BuildingPart`` (docs/importing.md, section "CityGML").

Stages: read the file (:mod:`dataset.importers.citygml.read`); triangulate every polygon
with its holes (:mod:`dataset.importers.citygml.polygons`); put the lowest ground-surface
point at z = 0 and the ground surface's x/y centre at the origin; check the surfaces face
out; find the facades and measure them in their planes
(:mod:`dataset.importers.citygml.facades`); mark which facades the data covers; assemble the
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

**Orientation.** World +y is the CRS's grid north; the truth's ``north_deg`` is the meridian
convergence at the building (:mod:`dataset.importers.citygml.grid_north`, ``north_source``
``"crs_convergence"``: 1.8 degrees for EPSG:32632 in Ingolstadt), so each facade's
``azimuth_deg`` is from true north.

**Seen straight on.** Each facade's ``visible_*_area_m2`` is its area less what other
surfaces of the building (balconies, bays, roof overhangs) hide from the front
(:mod:`dataset.importers.citygml.visible`).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import asdict, replace
from pathlib import Path

import numpy as np
import shapely
from shapely.geometry import Polygon

from dataset.importers.citygml.appearance import face_appearance
from dataset.importers.citygml.buildings import (
    LABEL_OF_KIND,
    benchmark_buildings,
    building_surfaces,
)
from dataset.importers.citygml.config import CityGmlConfig
from dataset.importers.citygml.context import party_wall_area_m2, read_neighbours
from dataset.importers.citygml.facades import FacadeRegions, Surface, building_facades
from dataset.importers.citygml.files import CityGmlError
from dataset.importers.citygml.grid_north import grid_north_deg
from dataset.importers.citygml.read import CityBuilding, CityModel, read_citygml
from dataset.importers.citygml.type import citygml_building_type
from dataset.importers.citygml.visible import hidden_share, with_visible_areas
from envelope.appearance import concatenate_appearances
from envelope.classes import NO_FACADE, SemanticClass
from envelope.footprint import polygon_to_geojson
from envelope.mesh import LabelledMesh
from envelope.orientation import azimuth_deg_from_normal
from envelope.truth import Building, BuildingTruth, FacadeTruth
from envelope.wwr import ClassAreas

WALL_SECTION_M = 0.3
"""Without a ground surface the footprint is what the walls enclose this high above the
lowest wall point: above a street's slope (up to ~0.2 m across a house here), below most
sills (higher, the gaps modellers leave around windows break the outline)."""
_ENCLOSING = ("wall", "roof", "ground", "closure", "outer_floor", "outer_ceiling")


def import_citygml(path: str | Path, *, config: CityGmlConfig | None = None
                   ) -> list[Building]:
    """Every building of a CityGML 2.0/3.0 file with ground truth (one per ``Building`` and
    ``BuildingPart``; a ``Building`` whose geometry is all in its parts gives none itself),
    each with the file's other buildings as its neighbours.

    Raises
    ------
    CityGmlError (a ValueError)
        As :func:`dataset.importers.citygml.read.read_citygml`, or a building with no wall
        surface (named by its ``gml:id``).
    """
    config = CityGmlConfig() if config is None else config
    return [building_from_citygml(model, b, config=config, neighbour_files=(path,))
            for model in [read_citygml(path)] for b in benchmark_buildings(model)]


def import_citygml_building(path: str | Path, name: str, *,
                            neighbour_files: Sequence[str | Path] | None = None,
                            config: CityGmlConfig | None = None) -> Building:
    """The building of ``path`` whose scene name is ``name`` (:func:`benchmark_buildings`),
    its neighbours read from ``neighbour_files`` (default: ``path`` alone): what a
    resumable run re-imports in a worker for one scene.

    Raises
    ------
    CityGmlError
        As :func:`import_citygml`, or no building of that name in the file.
    """
    config = CityGmlConfig() if config is None else config
    model = read_citygml(path)
    files = (path,) if neighbour_files is None else tuple(neighbour_files)
    for b in benchmark_buildings(model):
        if b.gml_id == name:
            return building_from_citygml(model, b, config=config, neighbour_files=files)
    raise CityGmlError(f"{path} holds no building {name!r}")


def building_from_citygml(model: CityModel, building: CityBuilding, *,
                          config: CityGmlConfig | None = None,
                          neighbour_files: Sequence[str | Path] = ()) -> Building:
    """One building's labelled mesh and truth (ids of the facades the data covers, from 1),
    with its appearance and, as its context, every other building of ``neighbour_files``
    (:mod:`dataset.importers.citygml.context`).

    Raises
    ------
    CityGmlError
        The building has no (non-degenerate) ``WallSurface`` polygon.
    """
    config = CityGmlConfig() if config is None else config
    where = f"{model.path}: building {building.attributes.get('gml:id', building.gml_id)}"
    warnings: Counter[str] = Counter(_warning_kind(w) for w in building.warnings)
    surfaces = building_surfaces(building, warnings)
    if not any(s.kind == "wall" for s in surfaces):
        raise CityGmlError(f"{where} has no WallSurface polygon with an area; a benchmark "
                           "building needs its walls (LoD2 or LoD3 boundary surfaces)")
    offset, ground_z, centre_xy = recentre_offset(surfaces, config, warnings)
    surfaces = [_moved(s, offset) for s in surfaces]
    if _enclosed_volume_m3(surfaces) < 0:
        surfaces = [_flipped(s) for s in surfaces]
        warnings["surfaces faced inwards (negative enclosed volume): all flipped"] += 1
    facades, opening_facade = building_facades(surfaces, config)
    covered = [k for k, f in enumerate(facades) if f.window.area + f.door.area > 0]
    facade_id = {k: i + 1 for i, k in enumerate(covered)}
    mesh = _mesh(surfaces, facades, opening_facade, facade_id)
    appearance = _appearance(model, building, surfaces, len(mesh.faces), offset, warnings)
    regions = {facade_id[k]: facades[k] for k in covered}
    truths = with_visible_areas(
        tuple(_facade_truth(facade_id[k], facades[k]) for k in covered), mesh, regions)
    totals = ClassAreas(*(sum(getattr(f, a) for f in truths)
                          for a in ("window_area_m2", "wall_area_m2", "door_area_m2")))
    footprint = _footprint(surfaces, mesh, warnings, where)
    context = read_neighbours(model, building.gml_id, [Path(f) for f in neighbour_files],
                              offset)
    party_m2 = party_wall_area_m2(surfaces, context)
    front_share = hidden_share(truths, mesh, regions, SemanticClass.OTHER)
    height = float(mesh.vertices_m[:, 2].max())
    north_deg = grid_north_deg(model.crs, *centre_xy)
    truth = BuildingTruth(
        id=building.gml_id, type=citygml_building_type(front_share, party_m2),
        floors=max(1, round(height / config.floor_height_m)), height_m=height,
        window_area_m2=totals.window_m2, facade_area_m2=totals.gross_m2,
        wall_area_m2=totals.wall_m2, door_area_m2=totals.door_m2, wwr=totals.wwr,
        footprint=polygon_to_geojson(footprint), footprint_area_m2=float(footprint.area),
        facades=truths, name=f"{model.path.name}#{building.gml_id}",
        facade_outlines_m={facade_id[k]: (tuple(map(tuple, facades[k].outline_m())),)
                           for k in covered},
        north_deg=north_deg, north_source="crs_convergence",
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
            "uncovered_facades": [_uncovered_record(f, surfaces, north_deg)
                                  for k, f in enumerate(facades) if k not in facade_id],
            "unassigned_openings": sorted(o for o in {s.owner_id for s in surfaces
                                                      if s.kind in ("window", "door")}
                                          if o not in opening_facade),
            "opening_fill_area_m2": float(sum(_fill_area(facades[k]) for k in covered)),
            "neighbours": [n.name for n in context],
            "party_wall_area_m2": party_m2,
            "front_hidden_share": front_share,
            "counts": dict(sorted(Counter(s.kind for s in surfaces).items())),
            "warnings": dict(sorted((k, v) for k, v in warnings.items() if v)),
            "import_config": asdict(config),
        },
    )
    return Building(mesh=mesh, truth=truth, appearance=appearance, context=context)


def _warning_kind(message: str) -> str:
    return message.split(": ", 1)[-1]


def recentre_offset(surfaces: list[Surface], config: CityGmlConfig, warnings: Counter
                    ) -> tuple[np.ndarray, float, tuple[float, float]]:
    """The shift (3,) that puts the lowest ground-surface point at z = 0 and the ground
    surface's x/y bounding-box centre at the origin (walls without a ground surface), that
    lowest z and that centre (file CRS, metres). A photos scene fitted to the city model
    (:mod:`dataset.importers.photos.city_target`) lands in the same frame."""
    ground = [s.tri.vertices_m for s in surfaces if s.kind == "ground"]
    if not ground:
        warnings["no GroundSurface: ground at the lowest wall point"] += 1
        ground = [s.tri.vertices_m for s in surfaces if s.kind == "wall"]
    pts = np.concatenate(ground)
    ground_z = float(pts[:, 2].min())
    lo, hi = pts[:, :2].min(axis=0), pts[:, :2].max(axis=0)
    centre = (float(lo[0] + hi[0]) / 2, float(lo[1] + hi[1]) / 2)
    if not config.recentre:
        return np.array([0.0, 0.0, -ground_z]), ground_z, centre
    return -np.array([centre[0], centre[1], ground_z]), ground_z, centre


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


def _appearance(model: CityModel, building: CityBuilding, surfaces: list[Surface],
                faces: int, offset: np.ndarray, warnings: Counter):
    """The mesh faces' textures and colours: the surfaces' (in :func:`_mesh`'s order), then
    none for the fillers."""
    by_id = {p.polygon_id: p for p in building.polygons}
    shown = [by_id[s.polygon_id] for s in surfaces if LABEL_OF_KIND[s.kind] is not None]
    counts = [len(s.tri.faces) for s in surfaces if LABEL_OF_KIND[s.kind] is not None]
    appearance = face_appearance(
        [model.looks.get(p.polygon_id) for p in shown], [(p.ring_ids, p.rings_m) for p in shown],
        [p.reversed for p in shown], counts, offset, model.path.parent, warnings)
    return concatenate_appearances([(appearance, sum(counts)), (None, faces - sum(counts))])


def _facade_truth(fid: int, f: FacadeRegions) -> FacadeTruth:
    areas = ClassAreas(float(f.window.area), float(f.wall.area), float(f.door.area))
    u0, v0, u1, v1 = f.gross.bounds
    return FacadeTruth(
        id=fid, normal=tuple(float(x) for x in f.normal), width_m=float(u1 - u0),
        height_m=float(v1 - v0), window_area_m2=areas.window_m2, wall_area_m2=areas.wall_m2,
        door_area_m2=areas.door_m2, facade_area_m2=areas.gross_m2, wwr=areas.wwr)


def _facade_record(f: FacadeRegions, surfaces: list[Surface]) -> dict:
    """Identity of a covered facade: its wall polygons and openings (its orientation is the
    truth's ``azimuth_deg``)."""
    return {"wall_polygon_ids": [surfaces[i].polygon_id for i in f.surfaces],
            "opening_ids": list(f.openings)}


def _uncovered_record(f: FacadeRegions, surfaces: list[Surface], north_deg: float) -> dict:
    return {"azimuth_deg": azimuth_deg_from_normal(f.normal, north_deg),
            "normal": [float(x) for x in f.normal],
            "wall_area_m2": float(f.wall.area), "width_m": float(f.gross.bounds[2]
                                                                  - f.gross.bounds[0]),
            "outline_m": [[float(x) for x in corner] for corner in f.outline_m()],
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
