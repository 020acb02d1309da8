"""envelope.orientation: azimuth from a normal and north, EnergyPlus bins at their exact
bounds; the truth's derived azimuths; the north an IFC file states.

Closed forms: a normal (sin a, cos a, 0) has azimuth a + north (mod 360); exact bin bounds
belong to the bin they start (EnergyPlus / OpenStudio / Honeybee: N is >= 315 or < 45).
"""

import math
from dataclasses import replace

import numpy as np
import pytest

from envelope.orientation import (
    BIN_CENTRE_DEG,
    ORIENTATION_BINS,
    azimuth_deg_from_normal,
    orientation_bin,
    true_north_xy_from_world,
)
from envelope.results import FacadeEstimate
from envelope.truth import BuildingTruth, read_building, write_building


@pytest.mark.parametrize("azimuth", [0.0, 30.0, 89.0, 90.0, 180.0, 225.5, 300.0, 359.0])
@pytest.mark.parametrize("north", [0.0, 20.0, -30.0, 400.0])
def test_azimuth_of_a_horizontal_normal(azimuth, north):
    a = math.radians(azimuth)
    got = azimuth_deg_from_normal((3 * math.sin(a), 3 * math.cos(a), 0.4), north)
    assert got == pytest.approx((azimuth + north) % 360.0, abs=1e-9)
    assert 0.0 <= got < 360.0


def test_world_axes_and_vertical_normals():
    assert azimuth_deg_from_normal((0, 1, 0)) == 0.0  # +y is north by convention
    assert azimuth_deg_from_normal((1, 0, 0)) == 90.0  # +x east
    assert azimuth_deg_from_normal((0, -1, 0)) == 180.0
    assert azimuth_deg_from_normal((-1, 0, 0)) == 270.0
    assert azimuth_deg_from_normal((0, 0, 1)) is None  # a roof has no azimuth
    assert azimuth_deg_from_normal((1e-9, 0, -1)) is None
    with pytest.raises(ValueError, match="3 finite numbers"):
        azimuth_deg_from_normal((float("nan"), 0, 0))
    with pytest.raises(ValueError, match="north_deg"):
        azimuth_deg_from_normal((1, 0, 0), float("inf"))


@pytest.mark.parametrize("azimuth, expected", [
    (0.0, "N"), (44.999999, "N"), (45.0, "E"), (134.999, "E"), (135.0, "S"), (224.9, "S"),
    (225.0, "W"), (314.9999, "W"), (315.0, "N"), (359.9999, "N"), (360.0, "N"), (-45.0, "N"),
    (-45.0001, "W"), (405.0, "E"), (-1e-17, "N"),
])
def test_bins_at_their_exact_bounds(azimuth, expected):
    assert orientation_bin(azimuth) == expected


def test_bin_centres_bin_to_themselves():
    assert [orientation_bin(BIN_CENTRE_DEG[b]) for b in ORIENTATION_BINS] == list(
        ORIENTATION_BINS)
    with pytest.raises(ValueError, match="finite"):
        orientation_bin(float("nan"))


def test_true_north_frame_puts_each_azimuth_on_the_map():
    for north in (0.0, 20.0, 137.0):
        for p in (0.0, 45.0, 200.0):
            world = np.array([math.sin(math.radians(p)), math.cos(math.radians(p))])
            x, y = true_north_xy_from_world(world, north)
            assert math.degrees(math.atan2(x, y)) % 360 == pytest.approx((p + north) % 360)
    pts = np.random.default_rng(0).normal(size=(5, 2))
    turned = true_north_xy_from_world(pts, 33.0)
    np.testing.assert_allclose(np.linalg.norm(turned, axis=1), np.linalg.norm(pts, axis=1))


def test_truth_derives_azimuths_from_north_and_reads_old_files(tmp_path):
    from metrics_helpers import make_truth

    truth = make_truth("a")  # facade 1 faces +x, facade 2 faces +y
    assert [(f.azimuth_deg, f.orientation) for f in truth.facades] == [(90.0, "E"), (0.0, "N")]
    assert (truth.north_deg, truth.north_source) == (0.0, "convention")
    turned = replace(truth, north_deg=-60.0, north_source="user")
    assert [f.orientation for f in turned.facades] == ["N", "W"]  # 30 and 300 degrees
    write_building(tmp_path / "building.json", turned)
    assert read_building(tmp_path / "building.json") == turned
    d = turned.to_json_dict()
    assert d["facades"][1]["orientation"] == "W" and d["north_source"] == "user"
    # A file written before these fields existed reads with the convention.
    old = truth.to_json_dict()
    for key in ("north_deg", "north_source"):
        del old[key]
    for f in old["facades"]:
        del f["azimuth_deg"], f["orientation"]
    assert BuildingTruth.from_json_dict(old) == truth
    # Stored azimuths never disagree with the normal and north: they are derived again.
    stale = turned.to_json_dict()
    stale["facades"][0]["azimuth_deg"] = 123.0
    assert BuildingTruth.from_json_dict(stale) == turned
    with pytest.raises(ValueError, match="north_source"):
        replace(truth, north_source="compass")


def test_facade_estimate_orientation_follows_its_azimuth():
    assert FacadeEstimate(id=1, wwr=0.2).orientation is None
    assert FacadeEstimate(id=1, wwr=0.2, azimuth_deg=135.0).orientation == "S"


@pytest.fixture(scope="module")
def box_ifc(tmp_path_factory):
    from dataset.examples.ifc_houses import box_house

    path = tmp_path_factory.mktemp("ifc") / "box.ifc"
    box_house(path)
    return path


def test_ifc_true_north_becomes_the_truths_north(box_ifc, tmp_path):
    """box_house's walls face -y (windows), +x, +y (door), -x; TrueNorth 30 degrees
    anticlockwise of +y turns them to 210, 120, 30, 300."""
    import ifcopenshell

    from dataset.importers.ifc.convert import import_ifc, north_of_ifc

    model = ifcopenshell.open(str(box_ifc))
    assert north_of_ifc(model) is None
    context = model.by_type("IfcGeometricRepresentationContext", include_subtypes=False)[0]
    context.TrueNorth = model.createIfcDirection((-math.sin(math.radians(30)),
                                                  math.cos(math.radians(30))))
    model.write(str(tmp_path / "north.ifc"))
    truth = import_ifc(tmp_path / "north.ifc", progress=False).truth
    assert truth.north_deg == pytest.approx(30.0)
    assert truth.north_source == "ifc_true_north"
    by_normal = {tuple(np.round(f.normal, 6)): f for f in truth.facades}
    assert by_normal[(0.0, -1.0, 0.0)].azimuth_deg == pytest.approx(210.0)
    assert by_normal[(1.0, 0.0, 0.0)].orientation == "E"  # 120
    assert by_normal[(0.0, 1.0, 0.0)].orientation == "N"  # 30
    assert by_normal[(-1.0, 0.0, 0.0)].orientation == "W"  # 300


def test_ifc_map_conversion_gives_grid_north(box_ifc):
    import ifcopenshell
    import ifcopenshell.api.georeference

    from dataset.importers.ifc.convert import north_of_ifc

    model = ifcopenshell.open(str(box_ifc))
    ifcopenshell.api.georeference.add_georeferencing(model)
    t = math.radians(25.0)  # project +x points 25 degrees clockwise of grid east
    ifcopenshell.api.georeference.edit_georeferencing(model, coordinate_operation={
        "XAxisAbscissa": math.cos(t), "XAxisOrdinate": -math.sin(t), "Eastings": 0.0,
        "Northings": 0.0, "OrthogonalHeight": 0.0})
    north_deg, source = north_of_ifc(model)
    assert (north_deg, source) == (pytest.approx(25.0), "ifc_map_conversion")
