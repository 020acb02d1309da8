"""Balcony models: slabs close the wall's contact holes, railings float as their own bodies."""

import numpy as np
import pytest
from building_checks import check_closed_bodies

from dataset.families.facade_geometry import WallFrame
from dataset.families.polygon_mesh import triangulate_faces
from dataset.families.realistic import make_realistic
from dataset.families.realistic_balcony import (
    RAILING_GAP_M,
    RAILING_INSET_M,
    RAILING_THICKNESS_M,
    SLAB_THICKNESS_M,
    balcony_faces,
)
from dataset.families.realistic_params import RealisticParams, default_realistic_params
from envelope.classes import NO_FACADE, SemanticClass


def test_balcony_parts_have_closed_form_areas():
    frame = WallFrame((0.0, 0.0), (10.0, 0.0))
    mesh = triangulate_faces(balcony_faces(frame, 2.0, 5.0, 3.0, 1.2, 1.0))
    areas = mesh.face_areas_m2()
    slab = 3.0 * 1.2 * 2 + 3.0 * SLAB_THICKNESS_M + 2 * 1.2 * SLAB_THICKNESS_M
    a, b = 2.0 + RAILING_INSET_M, 5.0 - RAILING_INSET_M
    e, f, t = RAILING_GAP_M, 1.2 - RAILING_INSET_M, RAILING_THICKNESS_M
    u_area = (b - a) * (f - e) - (b - a - 2 * t) * (f - t - e)
    u_perimeter = (b - a) + (b - a - 2 * t) + 2 * (f - e) + 2 * (f - t - e) + 2 * t
    railing = 2 * u_area + u_perimeter * (1.0 - RAILING_GAP_M)
    assert areas.sum() == pytest.approx(slab + railing, rel=1e-12)
    assert np.all(mesh.face_label == SemanticClass.OTHER)
    assert np.all(mesh.face_facade == NO_FACADE)
    # The slab sticks out in front of the wall (outward = -y) and its top is the floor level.
    assert mesh.vertices_m[:, 1].min() == pytest.approx(-1.2)


@pytest.mark.parametrize(("model", "bodies"), [("balcony_a", 1 + 30), ("balcony_b", 1 + 12)])
def test_railings_are_separate_bodies_and_contacts_leave_the_facade(model, bodies):
    p = default_realistic_params(model)
    building = make_realistic(p)
    assert check_closed_bodies(building) == bodies  # building + one railing per balcony
    t = building.truth
    contact = t.extra["balcony_contact_area_m2"]
    assert contact["1"] > 0 and contact["2"] == 0
    south = t.facade(1)
    gross = p.width_m * (p.floors * p.floor_height_m + p.roof_m)
    assert south.facade_area_m2 == pytest.approx(gross - contact["1"])


def test_balcony_models_need_two_floors():
    with pytest.raises(ValueError, match="floors >= 2"):
        make_realistic(RealisticParams("balcony_a", 14.0, 10.0, 1, 3.0, 1.0))
