"""A CityGML building among its neighbours: party walls, the building type, what a balcony
hides seen straight on, and the ``--context`` views (neighbours occlude, the truth stays).

Closed-form cases on box buildings written by :mod:`citygml_boxes`; one check on the real
Ingolstadt street (the lod3 preset's files).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from citygml_boxes import Box, write_boxes

from dataset.generate import main as generate_main
from dataset.importers.citygml.convert import import_citygml, import_citygml_building
from dataset.importers.citygml.type import citygml_building_type
from dataset.rendering.context import CLEARANCE_M, ViewMeshes
from dataset.rendering.render import render_ground_truth
from envelope.camera import Intrinsics, look_at
from envelope.classes import NO_FACADE, SemanticClass

# A street along x: the measured house A (front at y = 0, facing -y, a window), B against
# its right side (a party wall 10 m deep, 6 m high), C detached further along, D across the
# street (its back wall at y = -10 faces A) and a kiosk E on the pavement in front of A's
# left half. In A's world frame (its ground centred): A's front at y = -5, x in [-5, 5]; D's
# back wall at y = -15; E at x in [-5, -1], y in [-9, -7], 3 m high.
A = Box("A", (0, 10), (0, 10), 8, windows=((2, 1, 4, 3),))
B = Box("B", (10, 16), (0, 10), 6, windows=((1 + 10, 1, 3 + 10, 2.5),))
C = Box("C", (30, 40), (0, 10), 8, windows=((32, 1, 34, 3),))
D = Box("D", (0, 10), (-14, -10), 9)
E = Box("E", (0, 4), (-4, -2), 3)


@pytest.fixture(scope="module")
def street(tmp_path_factory):
    path = tmp_path_factory.mktemp("street") / "street.gml"
    write_boxes(path, [A, B, C, D, E])
    return {b.truth.id: b for b in import_citygml(path)}, path


def test_party_wall_is_the_shared_wall_area(street):
    buildings, _ = street
    assert buildings["A"].truth.extra["party_wall_area_m2"] == pytest.approx(10 * 6, rel=1e-9)
    assert buildings["B"].truth.extra["party_wall_area_m2"] == pytest.approx(10 * 6, rel=1e-9)
    assert buildings["C"].truth.extra["party_wall_area_m2"] == 0.0
    assert [buildings[n].truth.type for n in "ABC"] == ["terraced", "terraced", "detached"]
    assert buildings["D"].truth.facades == ()  # no window: no scene, but a neighbour
    assert "street.gml#D" in buildings["A"].truth.extra["neighbours"]


def test_type_rule_order_and_thresholds():
    assert citygml_building_type(0.02, 0.0) == "with_balconies"
    assert citygml_building_type(0.5, 200.0) == "with_balconies"  # balconies come first
    assert citygml_building_type(0.0199, 10.0) == "terraced"
    assert citygml_building_type(0.0, 9.99) == "detached"


def test_a_plate_in_front_hides_its_area_seen_straight_on(tmp_path):
    """A 4 m x 1 m parapet 1.5 m in front of the wall, over the lower half metre of a 2 m x
    2 m window: 1 m² of window and 3 m² of wall hidden; 4 m² of an 80 m² front is 5 %."""
    box = Box("P", (0, 10), (0, 10), 8, windows=((2, 1, 4, 3),), plate=(1, 5, 0.5, 1.5, 1.5))
    (b,) = import_citygml(write_boxes(tmp_path / "p.gml", [box]))
    (front,) = b.truth.facades
    assert front.window_area_m2 == pytest.approx(4.0, rel=1e-9)
    assert front.visible_window_area_m2 == pytest.approx(3.0, rel=1e-9)
    assert front.wall_area_m2 - front.visible_wall_area_m2 == pytest.approx(3.0, rel=1e-9)
    assert front.visible_door_area_m2 == 0.0
    assert b.truth.extra["front_hidden_share"] == pytest.approx(4.0 / 80.0, rel=1e-9)
    assert b.truth.type == "with_balconies"


def test_street_pose_moves_a_blocked_camera_in_front_of_the_neighbour(street):
    """Camera 30 m in front of A looking at it: D's back wall (y = -10) is in the way, so the
    camera moves to y = -10 + clearance; a camera that is not blocked stays."""
    buildings, _ = street
    a = buildings["A"]
    meshes = ViewMeshes(a, context=True)
    z = 4.0  # above the kiosk
    pose = look_at(np.array([0.0, -35.0, z]), np.array([0.0, 0.0, z]))
    moved = meshes.street_pose(pose)
    assert moved[:3, 3] == pytest.approx([0.0, -15.0 + CLEARANCE_M, z], abs=1e-6)
    assert np.array_equal(moved[:3, :3], pose[:3, :3])
    free = look_at(np.array([0.0, -8.0, z]), np.array([0.0, 0.0, z]))
    assert np.array_equal(meshes.street_pose(free), free)
    alone = ViewMeshes(a, context=False)
    assert np.array_equal(alone.street_pose(pose), pose)


def test_a_neighbour_occludes_pixels_and_labels_them_background(street):
    """A camera in the street looking at A's front: with context the kiosk hides part of
    it; those pixels become background with the kiosk's depth, nothing else changes."""
    buildings, _ = street
    a = buildings["A"]
    k = Intrinsics.from_fov(64, 64, 60.0)
    pose = look_at(np.array([0.0, -13.0, 2.0]), np.array([0.0, -5.0, 2.0]))
    alone = render_ground_truth(ViewMeshes(a, context=False).rendered, k, pose)
    context = render_ground_truth(ViewMeshes(a, context=True).rendered, k, pose)
    facade = alone.facade_ids != NO_FACADE
    hidden = facade & (context.facade_ids == NO_FACADE)
    assert hidden.sum() > 50
    assert np.all(context.labels[hidden] == SemanticClass.BACKGROUND)
    assert np.all(context.depth_z_m[hidden] > 0)
    assert np.all(context.depth_z_m[hidden] < alone.depth_z_m[hidden])
    same = ~hidden & (context.depth_z_m == alone.depth_z_m)
    assert np.array_equal(context.labels[same & facade], alone.labels[same & facade])


@pytest.mark.slow
def test_generate_with_context_keeps_the_truth(street, tmp_path):
    _, path = street
    tiny = ["--resolution", "32", "--views", "2", "--quiet"]
    assert generate_main(["--citygml", str(path), "--out", str(tmp_path / "alone"), *tiny]) == 0
    assert generate_main(["--citygml", str(path), "--out", str(tmp_path / "ctx"), "--context",
                          *tiny]) == 0
    for name in ("A", "B", "C"):
        assert (tmp_path / "alone" / name / "building.json").read_bytes() == (
            tmp_path / "ctx" / name / "building.json").read_bytes()
    frames = [json.loads((tmp_path / f / "A" / "transforms.json").read_text())["frames"]
              for f in ("alone", "ctx")]
    assert [f["file_path"] for f in frames[0]] == [f["file_path"] for f in frames[1]]
    assert any(not np.allclose(f["transform_matrix"], g["transform_matrix"])
               for f, g in zip(*frames))
    config = json.loads((tmp_path / "ctx" / "A" / "transforms.json").read_text())
    assert config["generator"]["config"]["context"] is True


@pytest.mark.slow
def test_real_street_neighbours_and_types():
    """On the shipped street: 4018207 shares both side walls (terraced), 4018149b's loggias
    hide a fifth of its front (with balconies), 4018133 stands free of the set's buildings."""
    from dataset.importers.citygml.context import files_near
    from dataset.importers.citygml.preset import LOD3_DIR, lod3_files

    files = lod3_files()
    types = {}
    for name in ("4018207", "4018149b", "4018133"):
        (own,) = [f for f in files if f.path == LOD3_DIR / name / f"{name}.xml.xz"]
        b = import_citygml_building(own.path, name, neighbour_files=files_near(own.bbox_m,
                                                                               files))
        types[name] = b.truth.type
        assert b.context and all(len(n.mesh.faces) for n in b.context)
    assert types == {"4018207": "terraced", "4018149b": "with_balconies",
                     "4018133": "detached"}


def test_the_source_reads_a_folder_as_one_city_model(tmp_path):
    """Two files 20 m apart and one 200 m away: each entry's building has the buildings of
    the files within 30 m as neighbours, and its inputs fingerprint those files."""
    from dataset.importers.citygml.source import CITYGML_SOURCE
    from dataset.importers.source import NoOptions

    write_boxes(tmp_path / "a.gml", [A])
    write_boxes(tmp_path / "b.gml", [Box("F", (30, 40), (0, 10), 8, windows=((32, 1, 34, 3),))])
    write_boxes(tmp_path / "c.gml", [Box("G", (230, 240), (0, 10), 8, windows=((232, 1, 234, 3),))])
    assert CITYGML_SOURCE.detect(tmp_path) and CITYGML_SOURCE.detect(tmp_path / "a.gml")
    entries = {e.name: e for e in CITYGML_SOURCE.read(tmp_path, NoOptions())}
    assert sorted(entries) == ["a", "b", "c"]  # one building a file: named after the file
    assert set(entries["a"].inputs) == {"citygml", "building", "neighbours"}
    assert len(entries["a"].inputs["neighbours"]) == 1 and entries["c"].inputs["neighbours"] == []
    assert [n.name for n in entries["a"].build().context] == ["b.gml#b"]
    assert entries["c"].build().context == ()
