"""The CityGML importer on real LoD3 buildings (tests/fixtures/citygml, Ingolstadt, CC BY-SA 4.0).

Closed-form checks: the mesh holds every polygon's area exactly, the facade regions add up,
the footprint is the ground surface, the walls' own section matches it, re-import is
byte-identical, and the covered rule picks the street facades one can see in the data.
"""

from __future__ import annotations

import lzma
from pathlib import Path

import numpy as np
import pytest
import shapely
import shapely.affinity
from paths import FIXTURES

from dataset.importers.citygml.convert import import_citygml
from dataset.importers.citygml.files import citygml_files, citygml_stem
from dataset.importers.citygml.grid_north import grid_north_deg
from dataset.importers.citygml.read import read_citygml
from envelope.classes import NO_FACADE, SemanticClass
from envelope.footprint import geojson_to_polygon
from envelope.mesh import write_labelled_ply
from envelope.polygons import newell_vector
from envelope.truth import write_building

FIXTURES = FIXTURES / "citygml"
IDS = ("4018259", "4018133", "4018149b")
AREA_RTOL = 1e-3  # the 0.1 %


def _fixture(building_id: str) -> Path:
    return FIXTURES / f"{building_id}.xml.xz"


@pytest.fixture(scope="module")
def imported():
    return {i: import_citygml(_fixture(i))[0] for i in IDS}


def _vector_area_m2(rings) -> float:
    """A planar polygon's area from its rings' Newell normals (exterior minus holes)."""
    n = newell_vector(rings[0])
    unit = n / np.linalg.norm(n)
    return float(0.5 * (n @ unit) - sum(abs(0.5 * newell_vector(h) @ unit) for h in rings[1:]))


def test_reads_version_crs_and_kinds():
    model = read_citygml(_fixture("4018149b"))
    assert model.version == "2.0" and model.crs == "EPSG:32632"
    (b,) = model.buildings
    assert b.gml_id == "4018149b" and b.attributes["dataAvailable"] == "NotSufficient"
    kinds = {p.kind for p in b.polygons}
    assert {"wall", "roof", "ground", "closure", "window", "installation"} <= kinds
    assert citygml_stem(_fixture("4018149b")) == "4018149b"
    assert {_fixture(i) for i in IDS} <= set(citygml_files(FIXTURES))


@pytest.mark.slow
@pytest.mark.parametrize("building_id", IDS)
def test_mesh_holds_every_polygon_area(imported, building_id):
    """Each class's triangle area equals the sum of its polygons' areas (to 0.1 %); windows
    and doors add the fillers of their holes' rims; closure surfaces are left out."""
    building, truth = imported[building_id], imported[building_id].truth
    model = read_citygml(_fixture(building_id))
    expected: dict[int, float] = {}
    kind_label = {"wall": 1, "window": 2, "roof": 3, "door": 4, "installation": 5,
                  "ground": 5, "outer_floor": 5, "outer_ceiling": 5}
    for p in model.buildings[0].polygons:
        if p.kind in kind_label:
            label = kind_label[p.kind]
            expected[label] = expected.get(label, 0.0) + _vector_area_m2(p.rings_m)
    areas = building.mesh.face_areas_m2()
    fill = truth.extra["opening_fill_area_m2"]
    for label, area in expected.items():
        got = float(areas[building.mesh.face_label == label].sum())
        if label in (SemanticClass.WINDOW, SemanticClass.DOOR):
            got -= fill * (label == SemanticClass.WINDOW)  # these fixtures fill windows only
        assert got == pytest.approx(area, rel=AREA_RTOL), (label, got, area)


@pytest.mark.parametrize("building_id", IDS)
def test_facade_areas_add_up(imported, building_id):
    truth = imported[building_id].truth
    for f in truth.facades:
        assert f.facade_area_m2 == pytest.approx(
            f.wall_area_m2 + f.window_area_m2 + f.door_area_m2, rel=1e-12)
        assert f.window_area_m2 + f.door_area_m2 > 0  # covered: an opening is modelled
        assert f.width_m > 0 and f.height_m > 0
    assert truth.window_area_m2 == pytest.approx(sum(f.window_area_m2 for f in truth.facades))
    assert truth.wwr == pytest.approx(truth.window_area_m2 / truth.facade_area_m2)


def test_wall_area_is_its_polygons_less_the_frames_on_them(imported):
    """4018259's street facade: its windows fill holes in its wall polygons, and some frames
    lap 2-4 cm over the holes' edges onto the wall; so the wall area is the polygons' area
    (with their holes) less those laps: no more, and less by under 0.5 %."""
    truth = imported["4018259"].truth
    model = read_citygml(_fixture("4018259"))
    polygons = {p.polygon_id: p for p in model.buildings[0].polygons}
    street = max(truth.facades, key=lambda f: f.facade_area_m2)
    walls = [polygons[i] for i in truth.extra["facades"][str(street.id)]["wall_polygon_ids"]]
    polygons_m2 = sum(_vector_area_m2(p.rings_m) for p in walls)
    assert polygons_m2 * (1 - 5e-3) < street.wall_area_m2 <= polygons_m2 * (1 + 1e-9)


@pytest.mark.parametrize("building_id", IDS)
def test_ground_at_zero_and_offset_maps_back(imported, building_id):
    building = imported[building_id]
    extra = building.truth.extra
    assert extra["crs"] == "EPSG:32632"
    model = read_citygml(_fixture(building_id))
    ground_z = min(p.rings_m[0][:, 2].min() for p in model.buildings[0].polygons
                   if p.kind == "ground")
    assert ground_z + extra["offset_m"][2] == pytest.approx(0.0, abs=1e-9)
    first = model.buildings[0].polygons[0].rings_m[0][0]
    offset = np.asarray(extra["offset_m"])
    assert np.any(np.all(np.isclose(building.mesh.vertices_m - offset, first, atol=1e-9),
                         axis=1))
    assert extra["ground_z_m"] == pytest.approx(-offset[2])


@pytest.mark.parametrize("building_id", IDS)
def test_footprint_is_the_ground_surface(imported, building_id):
    building = imported[building_id]
    footprint = geojson_to_polygon(building.truth.footprint)
    model = read_citygml(_fixture(building_id))
    offset = np.asarray(building.truth.extra["offset_m"])
    ground = shapely.union_all([shapely.Polygon(p.rings_m[0][:, :2] + offset[:2])
                                for p in model.buildings[0].polygons if p.kind == "ground"])
    iou = footprint.intersection(ground).area / footprint.union(ground).area
    assert iou >= 0.99, iou
    assert building.truth.footprint_area_m2 == pytest.approx(footprint.area)


def test_footprint_from_walls_without_ground_surface(tmp_path, imported):
    """Without its GroundSurface, 4018149b's footprint is the walls' section 0.3 m up: IoU
    with the (removed) ground surface >= 0.99."""
    from lxml import etree

    with lzma.open(_fixture("4018149b")) as fh:
        tree = etree.parse(fh)
    for el in list(tree.getroot().iter("{*}GroundSurface")):
        holder = el.getparent()
        holder.getparent().remove(holder)
    path = tmp_path / "no_ground.gml"
    tree.write(str(path))
    building = import_citygml(path)[0]
    assert "no GroundSurface" in " ".join(building.truth.extra["warnings"])
    ground = geojson_to_polygon(imported["4018149b"].truth.footprint)
    walls = geojson_to_polygon(building.truth.footprint)
    shift = np.asarray(building.truth.extra["offset_m"]) - np.asarray(
        imported["4018149b"].truth.extra["offset_m"])
    walls = shapely.affinity.translate(walls, -shift[0], -shift[1])
    assert walls.intersection(ground).area / walls.union(ground).area >= 0.99


def test_import_twice_gives_identical_files(tmp_path):
    for run in ("a", "b"):
        building = import_citygml(_fixture("4018133"))[0]
        (tmp_path / run).mkdir()
        write_building(tmp_path / run / "building.json", building.truth)
        write_labelled_ply(tmp_path / run / "mesh.ply", building.mesh)
    for name in ("building.json", "mesh.ply"):
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes()


def test_covered_rule_on_a_street_house(imported):
    """4018259 stands with its street front facing SSE (azimuth ~167 degrees from true north,
    ~165 from grid north): that facade carries every window but the bay's; the backyard
    wall (~347) and the side walls against the neighbours (~77, ~264) have none and are not
    covered."""
    truth = imported["4018259"].truth
    street = max(truth.facades, key=lambda f: f.facade_area_m2)
    assert street.azimuth_deg == pytest.approx(164.8 + 1.82, abs=0.5)
    assert street.orientation == "S"
    assert street.window_area_m2 / truth.window_area_m2 > 0.9
    uncovered = sorted(round(u["azimuth_deg"]) for u in truth.extra["uncovered_facades"])
    assert uncovered == [77, 77, 264, 347]
    assert all(u["wall_area_m2"] > 0 for u in truth.extra["uncovered_facades"])
    # Uncovered walls stay in the mesh as wall, without a facade id (no views, no truth).
    mesh = imported["4018259"].mesh
    assert np.any((mesh.face_label == SemanticClass.WALL) & (mesh.face_facade == NO_FACADE))
    assert set(np.unique(mesh.face_facade)) == {0, *(f.id for f in truth.facades)}


def test_data_available_is_recorded_not_used(imported):
    assert imported["4018259"].truth.extra["data_available"] == "Sufficient"
    assert imported["4018149b"].truth.extra["data_available"] == "NotSufficient"
    assert imported["4018149b"].truth.facades  # NotSufficient buildings keep their facades


def test_north_is_the_utm_grid_convergence(imported):
    """World +y is EPSG:32632's grid north; north_deg is the meridian convergence at the
    building. Closed form on the sphere: gamma = atan(tan(lon - 9 E) sin(lat)), within
    0.01 degrees of the ellipsoidal value at these distances from the meridian."""
    import math

    import pyproj

    truth = imported["4018259"].truth
    assert truth.north_source == "crs_convergence"
    x, y = -np.asarray(truth.extra["offset_m"][:2])
    lon, lat = pyproj.Transformer.from_crs("EPSG:32632", "EPSG:4326",
                                           always_xy=True).transform(x, y)
    gamma = math.degrees(math.atan(math.tan(math.radians(lon - 9.0))
                                   * math.sin(math.radians(lat))))
    assert truth.north_deg == pytest.approx(gamma, abs=0.01)
    assert truth.north_deg == pytest.approx(1.82, abs=0.01)  # Ingolstadt, 11.4 E 48.8 N
    assert grid_north_deg("EPSG:32632", 500000.0, 5_400_000.0) == pytest.approx(0.0, abs=1e-9)
    west = grid_north_deg("EPSG:32632", 300000.0, 5_400_000.0)
    assert west < 0  # west of the central meridian grid north lies anticlockwise of true
    with pytest.raises(ValueError, match="not projected"):
        grid_north_deg("EPSG:4326", 11.0, 48.0)
    with pytest.raises(ValueError, match="unknown to PROJ"):
        grid_north_deg("EPSG:999999", 0.0, 0.0)


def test_classes_and_what_is_left_out(imported):
    mesh = imported["4018149b"].mesh
    labels = set(np.unique(mesh.face_label).tolist())
    assert labels == {1, 2, 3, 5}  # wall, window, roof, other (installations, ground, floors)
    # Outward normals: the walls' area-weighted normals point away from the footprint centre.
    centre = shapely.centroid(geojson_to_polygon(imported["4018149b"].truth.footprint))
    wall = mesh.face_label == SemanticClass.WALL
    tri = mesh.triangles_m[wall]
    out = tri.mean(axis=1)[:, :2] - np.array([centre.x, centre.y])
    facing = np.einsum("ij,ij->i", mesh.face_normals()[wall][:, :2], out)
    assert (mesh.face_areas_m2()[wall] * np.sign(facing)).sum() > 0.8 * mesh.face_areas_m2()[
        wall].sum()


@pytest.mark.parametrize(("field", "value", "message"), [
    ("max_tilt_deg", 95.0, "max_tilt_deg must be in"),
    ("gap_tolerance_m", -1.0, "gap_tolerance_m must be >= 0"),
    ("min_hole_cover", 0.0, "min_hole_cover must be in"),
    ("max_opening_depth_m", 0.0, "max_opening_depth_m must be > 0"),
])
def test_config_rejects_bad_tolerances(field, value, message):
    from dataset.importers.citygml.config import CityGmlConfig

    with pytest.raises(ValueError, match=message):
        CityGmlConfig(**{field: value})
