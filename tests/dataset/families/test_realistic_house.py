"""The house: gable walls in closed form, the chimney as its own closed body."""

import numpy as np
import pytest
from building_checks import check_closed_bodies

from dataset.families.realistic import make_realistic
from dataset.families.realistic_house import (
    CHIMNEY_ABOVE_RIDGE_M,
    ROOF_SHELL_GAP_M,
    ROOF_SHELL_THICKNESS_M,
    house_layout,
)
from dataset.families.realistic_params import RealisticParams
from envelope.classes import SemanticClass


def test_house_facades_and_roof_are_closed_form():
    p = RealisticParams("house", width_m=12.0, depth_m=9.0, floors=3, floor_height_m=3.0,
                        roof_m=5.0)
    t = make_realistic(p).truth
    eave, rise = 9.0, 5.0
    cos = 4.5 / np.hypot(4.5, rise)  # of the roof pitch
    shell = (ROOF_SHELL_GAP_M + ROOF_SHELL_THICKNESS_M) / cos
    assert t.height_m == pytest.approx(eave + rise + shell)
    assert t.extra["roof"]["ridge_height_m"] == pytest.approx(eave + rise)
    south, east, north, west = t.facades
    assert south.facade_area_m2 == pytest.approx(12.0 * eave)
    assert east.facade_area_m2 == pytest.approx(9.0 * eave + 9.0 * rise / 2)
    assert east.height_m == pytest.approx(eave + rise)
    assert south.door_area_m2 == north.door_area_m2 == pytest.approx(1.1 * 2.2)
    # Three window sizes: large ground floor, typical, small (back ground floor and attic).
    sizes = {round(o.area_m2, 6) for w in house_layout(p).walls for o in w.openings
             if o.kind == "window"}
    assert len(sizes) >= 3
    assert t.extra["roof"]["kind"] == "gable"
    assert t.extra["chimney_top_m"] == pytest.approx(eave + rise + CHIMNEY_ABOVE_RIDGE_M)
    assert t.extra["chimney_top_m"] > t.height_m


def test_chimney_and_roof_slab_are_separate_closed_bodies():
    building = make_realistic(RealisticParams("house"))
    assert check_closed_bodies(building) == 3  # house, roof slab, chimney
    mesh, t = building.mesh, building.truth
    other = mesh.face_label == SemanticClass.OTHER
    top = mesh.triangles_m[other][..., 2].max()
    assert top == pytest.approx(t.extra["roof"]["ridge_height_m"] + CHIMNEY_ABOVE_RIDGE_M)
    roof = mesh.face_label == SemanticClass.ROOF
    assert mesh.triangles_m[roof][..., 2].max() == pytest.approx(t.height_m)
