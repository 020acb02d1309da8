"""The facade seen straight on: hidden areas behind railings and under eaves in closed form."""

import json

import numpy as np
import pytest

from dataset.families.facade_geometry import WallFrame, WallSpec, rectangle_outline, wall_faces
from dataset.families.polygon_mesh import triangulate_faces
from dataset.families.realistic import make_realistic
from dataset.families.realistic_balcony import (
    BALCONY_DOOR_SILL_M,
    BAY_M,
    MARGIN_M,
    RAILING_GAP_M,
    RAILING_INSET_M,
    balcony_faces,
)
from dataset.families.realistic_house import EAVES_OVERHANG_M, ROOF_SHELL_GAP_M
from dataset.families.realistic_params import RealisticParams, default_realistic_params
from dataset.families.skyscraper import SkyscraperParams, make_skyscraper
from dataset.families.visible_facade import hidden_facade_areas_m2
from envelope.classes import SemanticClass
from envelope.truth import read_building, write_building
from envelope.wwr import ClassAreas

WALL, WINDOW, DOOR = SemanticClass.WALL, SemanticClass.WINDOW, SemanticClass.DOOR


def test_a_railing_hides_its_rectangle_of_the_wall_behind_it():
    frame = WallFrame((0.0, 0.0), (10.0, 0.0))  # outward normal -y
    wall = WallSpec(frame, 1, rectangle_outline(10.0, 6.0), contacts_uv=((2.0, 2.8, 5.0, 3.0),))
    mesh = triangulate_faces(wall_faces(wall) + balcony_faces(frame, 2.0, 5.0, 3.0, 1.2, 1.0))
    hidden = hidden_facade_areas_m2(mesh)
    railing = (3.0 - 2 * RAILING_INSET_M) * (1.0 - RAILING_GAP_M)
    assert hidden[1][WALL] == pytest.approx(railing, rel=1e-9)
    assert hidden[1][WINDOW] == hidden[1][DOOR] == 0.0


def test_continuous_balconies_hide_wall_and_balcony_doors_in_closed_form():
    p = default_realistic_params("balcony_b")
    t = make_realistic(p).truth
    railing_h = 1.1  # continuous balconies (realistic_balcony.balcony_layout)
    for fid, length in ((1, p.width_m), (3, p.width_m)):
        f = t.facade(fid)
        balconies = p.floors - 1
        cols = max(1, round((length - 2 * MARGIN_M) / BAY_M))
        railing = (length - 0.8 - 2 * RAILING_INSET_M) * (railing_h - RAILING_GAP_M)
        window = cols * p.window_width_m * (railing_h - BALCONY_DOOR_SILL_M)
        assert f.window_area_m2 - f.visible_window_area_m2 == pytest.approx(balconies * window)
        assert f.wall_area_m2 - f.visible_wall_area_m2 == pytest.approx(
            balconies * (railing - window))
        assert f.visible_door_area_m2 == f.door_area_m2
    for fid in (2, 4):  # the end facades have no balcony: all of them is seen
        f = t.facade(fid)
        assert (f.visible_window_area_m2, f.visible_wall_area_m2) == (f.window_area_m2,
                                                                      f.wall_area_m2)


def test_the_roof_slab_hides_a_strip_under_the_eaves_of_the_house():
    p = RealisticParams("house", width_m=12.0, depth_m=9.0, floors=3, floor_height_m=3.0,
                        roof_m=5.0)
    t = make_realistic(p).truth
    tan = 5.0 / 4.5
    strip = EAVES_OVERHANG_M * tan - ROOF_SHELL_GAP_M * np.hypot(1.0, tan)
    for fid in (1, 3):
        f = t.facade(fid)
        assert f.wall_area_m2 - f.visible_wall_area_m2 == pytest.approx(12.0 * strip)
        assert f.visible_window_area_m2 == f.window_area_m2
    for fid in (2, 4):  # the slab floats above the gables' roof line
        assert t.facade(fid).visible_wall_area_m2 == t.facade(fid).wall_area_m2


def test_a_plain_block_is_seen_whole_and_the_fields_round_trip(tmp_path):
    t = make_skyscraper(SkyscraperParams()).truth
    assert t.visible_areas_m2() == ClassAreas(t.window_area_m2, t.wall_area_m2, t.door_area_m2)
    write_building(tmp_path / "building.json", t)
    assert read_building(tmp_path / "building.json") == t
    old = json.loads((tmp_path / "building.json").read_text())
    for f in old["facades"]:  # a file written before the visible truth existed
        for key in ("visible_window_area_m2", "visible_wall_area_m2", "visible_door_area_m2"):
            del f[key]
    (tmp_path / "old.json").write_text(json.dumps(old))
    older = read_building(tmp_path / "old.json")
    assert older.facades[0].visible_wall_area_m2 is None
    assert older.visible_areas_m2() is None
