"""dataset.importers.ifc.convert on real exports: ArchiCAD 20 (IFC4), Revit 2011 and 2021
(IFC2X3), IfcOpenShell (IFC4) -- tests/fixtures/ifc_real/SOURCE.md.

Each model is checked against measures the importer does not use
(:mod:`dataset.importers.ifc.checks`): its windows' declared OverallWidth x OverallHeight, the
facade and WWR on orthographic elevations, and the plan projection of the elements standing
at the footprint height. The values measured (bench/ifc_corpus.py prints the same) are in each
test's docstring; the bounds are the issue's (windows within 5 % of the declared sizes) and,
for the elevations, 5 % of the facade and 0.01 of WWR, footprint IoU 0.98.
"""

from __future__ import annotations

import lzma

import numpy as np
import pytest
from paths import FIXTURES

from dataset.importers.ifc.checks import elevation_areas, footprint_iou, plan_footprint
from dataset.importers.ifc.convert import building_from_ifc, read_ifc
from dataset.importers.import_config import ImportConfig
from envelope.classes import NO_FACADE, SemanticClass

FIXTURES = FIXTURES / "ifc_real"


def _import(name: str, tmp_path_factory):
    path = tmp_path_factory.mktemp("ifc_real") / name
    path.write_bytes(lzma.decompress((FIXTURES / f"{name}.xz").read_bytes()))
    model = read_ifc(path, progress=False)
    return model, building_from_ifc(model, path)


def _check_against_independent_measures(model, building, *, footprint_m2: float):
    t = building.truth
    windows = [w for w in t.extra["ifc"]["windows"] if w["declared_area_m2"]]
    declared = sum(w["declared_area_m2"] for w in windows)
    assert sum(w["measured_area_m2"] for w in windows) == pytest.approx(declared, rel=0.05)
    elevations = elevation_areas(building.mesh)
    assert t.facade_area_m2 == pytest.approx(elevations["facade_m2"], rel=0.05)
    assert t.wwr == pytest.approx(elevations["wwr"], abs=0.01)
    plan = plan_footprint(model, t.extra["ground_z_m"] + ImportConfig().footprint_height_m)
    assert footprint_iou(plan, t) >= 0.98
    assert t.footprint_area_m2 == pytest.approx(footprint_m2, rel=0.01)


@pytest.mark.slow
def test_ifcopenshell_house_windows_made_of_parts(tmp_path_factory):
    """IfcOpenHouse: each IfcWindow is an aggregate of four members and a glass plate
    (no geometry of its own) declaring 1.86 x 1.60 m. Measured: windows 14.58 m² v 14.88
    declared (-2.0 %: the frame's outer edge sits in the reveal), facade 98.98 v 97.2 m² on
    the elevations, WWR 0.1474 v 0.1514, footprint 53.4 v 53.6 m² in plan (IoU 0.997)."""
    model, building = _import("IfcOpenHouse_IFC4.ifc", tmp_path_factory)
    windows = building.truth.extra["ifc"]["windows"]
    assert len(windows) == 5
    assert {round(w["declared_area_m2"], 6) for w in windows} == {round(1.86 * 1.6, 6)}
    _check_against_independent_measures(model, building, footprint_m2=53.4)


@pytest.mark.slow
def test_revit_duplex_with_a_foundation_storey(tmp_path_factory):
    """Revit 2011's duplex (refused before: 'the section at z = 0.050 m holds no solid'):
    the ground is storey 'Level 1' at 0.00, the foundation storey 'T/FDN' at -1.25 m is
    below it; interior walls and doors (IsExternal = False) are not facade."""
    model, building = _import("duplex.ifc", tmp_path_factory)
    ground = building.truth.extra["ifc"]["ground"]
    assert (ground["storey"], ground["z_m"]) == ("Level 1", 0.0)
    assert [s["name"] for s in ground["below_grade_storeys"]] == ["T/FDN"]
    mesh = building.mesh
    assert mesh.triangles_m[mesh.face_facade != NO_FACADE][:, :, 2].min() >= -1e-9
    _check_against_independent_measures(model, building, footprint_m2=156.7)


@pytest.mark.slow
def test_revit_curtain_wall_without_a_roof(tmp_path_factory):
    """Revit 2021's sample: a curtain wall of plates (window) and members (wall), no roof
    element (a virtual lid closes it for the rays), every element flagged IsExternal =
    False (so the flag is not used)."""
    model, building = _import("tested_sample_project.ifc", tmp_path_factory)
    t = building.truth
    assert t.extra["bodies"]["virtual_lid"]
    plates = [i for i, e in enumerate(model.elements) if e.ifc_type == "IfcPlate"]
    assert plates and all(model.elements[i].label == SemanticClass.WINDOW for i in plates)
    assert t.window_area_m2 > sum(w["measured_area_m2"] for w in t.extra["ifc"]["windows"])
    assert not np.isin(model.mesh.face_label, [SemanticClass.ROOF]).any()
    _check_against_independent_measures(model, building, footprint_m2=124.7)


@pytest.mark.slow
def test_archicad_house(tmp_path_factory):
    """ArchiCAD 20's FZK-Haus, IFC4: 11 windows declaring 23.60 m²."""
    model, building = _import("AC20-FZK-Haus.ifc", tmp_path_factory)
    assert len(building.truth.extra["ifc"]["windows"]) == 11
    _check_against_independent_measures(model, building, footprint_m2=119.4)
