"""CityGML 3.0: the OGC's LoD3 example building, written in 2.0 and in 3.0, imports to the same
truth (tests/fixtures/citygml/ogc, MIT)."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest
from paths import FIXTURES

from dataset.importers.citygml.convert import import_citygml
from dataset.importers.citygml.read import read_citygml
from envelope.classes import SemanticClass

OGC = FIXTURES / "citygml" / "ogc"
V2, V3 = OGC / "Building_LOD3-EPSG25832.v2.gml.xz", OGC / "Building_LOD3-EPSG25832.v3.gml.xz"


def test_both_versions_read_the_same_exterior():
    m2, m3 = read_citygml(V2), read_citygml(V3)
    assert (m2.version, m3.version) == ("2.0", "3.0")
    assert m2.crs == m3.crs == "EPSG:25832"
    kinds2 = Counter(p.kind for p in m2.buildings[0].polygons)
    kinds3 = Counter(p.kind for p in m3.buildings[0].polygons if p.kind != "interior")
    assert kinds2 == kinds3 == Counter(wall=16, roof=4, window=2, ground=1, door=1)
    assert any(p.kind == "interior" for p in m3.buildings[0].polygons)  # rooms, furniture


@pytest.mark.slow
def test_both_versions_import_to_the_same_truth():
    (b2,), (b3,) = import_citygml(V2), import_citygml(V3)
    t2, t3 = b2.truth, b3.truth
    for key in ("window_area_m2", "door_area_m2", "wall_area_m2", "facade_area_m2",
                "footprint_area_m2", "height_m"):
        assert getattr(t3, key) == pytest.approx(getattr(t2, key), rel=1e-9), key
    assert len(t2.facades) == len(t3.facades) == 2
    for f2, f3 in zip(t2.facades, t3.facades):
        np.testing.assert_allclose(f3.normal, f2.normal, atol=1e-9)
        assert f3.wwr == pytest.approx(f2.wwr, rel=1e-9)
    # Same surfaces, same orientation: the reversed OrientableSurfaces of 3.0 are undone.
    for label in (SemanticClass.WALL, SemanticClass.WINDOW, SemanticClass.ROOF):
        n2 = (b2.mesh.face_normals() * b2.mesh.face_areas_m2()[:, None])[
            b2.mesh.face_label == label].sum(axis=0)
        n3 = (b3.mesh.face_normals() * b3.mesh.face_areas_m2()[:, None])[
            b3.mesh.face_label == label].sum(axis=0)
        np.testing.assert_allclose(n3, n2, atol=1e-6)
    # The house: 2 windows (3 m²) and a door (2 m²) on two of its four walls.
    assert t3.window_area_m2 == pytest.approx(3.0) and t3.door_area_m2 == pytest.approx(2.0)
