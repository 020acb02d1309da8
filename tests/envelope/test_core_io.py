"""Round trips of the shared core: camera projection, labelled PLY, images, transforms.json, WWR."""

import json
from dataclasses import replace

import numpy as np
import pytest
import trimesh

from envelope.camera import (
    Intrinsics,
    look_at,
    project_world_to_image,
    unproject_depth_to_world,
)
from envelope.classes import SemanticClass, class_id_from_name
from envelope.mesh import LabelledMesh, area_by_class_m2, read_labelled_ply, write_labelled_ply
from envelope.results import FacadeEstimate, MethodResult, read_result, write_result
from envelope.scene_record import Frame, Scene
from envelope.scenes.images import (
    read_depth_m,
    read_facade_ids,
    read_labels,
    read_normals,
    read_rgb,
    write_depth_m,
    write_facade_ids,
    write_labels,
    write_normals,
    write_rgb,
)
from envelope.scenes.scene import read_scene, write_transforms


def test_project_unproject_round_trip():
    k = Intrinsics.from_fov(64, 48, 60.0)
    pose = look_at([10.0, -5.0, 3.0], [0.0, 0.0, 2.0])
    rng = np.random.default_rng(0)
    uv = rng.uniform([0, 0], [64, 48], size=(100, 2))
    depth = rng.uniform(1, 30, size=100)
    p = unproject_depth_to_world(uv, depth, k, pose)
    uv2, depth2 = project_world_to_image(p, k, pose)
    np.testing.assert_allclose(uv2, uv, atol=1e-9)
    np.testing.assert_allclose(depth2, depth, rtol=1e-12)


def test_look_at_centre_pixel_sees_target():
    k = Intrinsics.from_fov(65, 65, 50.0)
    pose = look_at([0.0, -10.0, 1.0], [0.0, 0.0, 1.0])
    uv, depth = project_world_to_image(np.array([0.0, 0.0, 1.0]), k, pose)
    np.testing.assert_allclose(uv, [32.5, 32.5], atol=1e-9)
    assert depth == pytest.approx(10.0)
    # +z world projects upward in the image (smaller v): OpenGL camera, +y up.
    uv_up, _ = project_world_to_image(np.array([0.0, 0.0, 2.0]), k, pose)
    assert uv_up[1] < 32.5


def test_labelled_ply_round_trips_through_trimesh(tmp_path):
    box = trimesh.creation.box([2.0, 3.0, 4.0])
    labels = np.arange(12) % 6
    facades = np.arange(12) // 2
    mesh = LabelledMesh(box.vertices, box.faces, labels, facades)
    write_labelled_ply(tmp_path / "m.ply", mesh)
    back = read_labelled_ply(tmp_path / "m.ply")
    np.testing.assert_array_equal(back.face_label, labels)
    np.testing.assert_array_equal(back.face_facade, facades)
    np.testing.assert_allclose(back.vertices_m, mesh.vertices_m)
    tm = trimesh.load(tmp_path / "m.ply", process=False)
    assert tm.is_watertight
    assert tm.area == pytest.approx(2 * (6 + 8 + 12))
    # Area bookkeeping: faces with facade id 0 are not facade.
    by_class = area_by_class_m2(back)
    assert by_class[SemanticClass.WINDOW] == pytest.approx(back.face_areas_m2()[labels == 2].sum())


def test_ply_without_labels_is_refused(tmp_path):
    trimesh.creation.box().export(tmp_path / "plain.ply")
    with pytest.raises(ValueError, match="label"):
        read_labelled_ply(tmp_path / "plain.ply")


def test_images_round_trip(tmp_path):
    rng = np.random.default_rng(1)
    rgb = rng.integers(0, 256, (8, 9, 3), dtype=np.uint8)
    write_rgb(tmp_path / "a.png", rgb)
    np.testing.assert_array_equal(read_rgb(tmp_path / "a.png"), rgb)
    depth = rng.uniform(0.5, 60, (8, 9))
    depth[0, 0] = 0
    write_depth_m(tmp_path / "d.png", depth, 0.001)
    back = read_depth_m(tmp_path / "d.png", 0.001)
    assert back[0, 0] == 0
    np.testing.assert_allclose(back, depth, atol=0.0005 + 1e-6)
    with pytest.raises(ValueError, match="16-bit range"):
        write_depth_m(tmp_path / "d.png", depth * 10, 0.001)
    labels = rng.integers(0, 6, (8, 9))
    write_labels(tmp_path / "s.png", labels)
    np.testing.assert_array_equal(read_labels(tmp_path / "s.png"), labels)
    ids = rng.integers(0, 300, (8, 9))
    write_facade_ids(tmp_path / "i.png", ids)
    np.testing.assert_array_equal(read_facade_ids(tmp_path / "i.png"), ids)
    n = rng.normal(size=(8, 9, 3))
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    n[1, 1] = 0
    write_normals(tmp_path / "n.png", n)
    np.testing.assert_allclose(read_normals(tmp_path / "n.png"), n, atol=2e-5)
    with pytest.raises(ValueError, match="does not exist"):
        read_rgb(tmp_path / "missing.png")


def test_transforms_round_trip(tmp_path):
    k = Intrinsics.from_fov(32, 24, 55.0)
    frames = (
        Frame("images/0.png", look_at([5, 0, 2], [0, 0, 1]), k, "train",
              depth_file_path="depth/0.png", semantic_file_path="semantics/0.png"),
        Frame("images/1.png", look_at([0, 5, 2], [0, 0, 1]), k.scaled(2), "ideal", facade_id=3),
    )
    scene = Scene(root=tmp_path, frames=frames)
    write_transforms(tmp_path, scene)
    back = read_scene(tmp_path, validate=False)  # JSON only: no image files
    assert len(back.frames) == 2
    for a, b in zip(frames, back.frames):
        np.testing.assert_allclose(a.world_from_camera, b.world_from_camera)
        assert (a.file_path, a.intrinsics, a.split, a.facade_id) == (
            b.file_path, b.intrinsics, b.split, b.facade_id)
        assert a.depth_file_path == b.depth_file_path
    assert back.frames_in("ideal")[0].facade_id == 3


def test_read_scene_without_transforms_says_how_to_make_one(tmp_path):
    with pytest.raises(ValueError, match="dataset.generate"):
        read_scene(tmp_path)


def test_class_names():
    assert class_id_from_name("Window") == SemanticClass.WINDOW
    with pytest.raises(ValueError, match="unknown semantic class"):
        class_id_from_name("glass")


def test_result_file_round_trip(tmp_path):
    r = MethodResult(
        scene="s", method="2D-SS", protocol="ideal", wwr=0.3, window_area_m2=30.0,
        facade_area_m2=100.0, facades=(FacadeEstimate(id=1, wwr=0.3), FacadeEstimate(
            id=2, wwr=None, missing=True, reason="no usable view")),
        config={"a": 1, "heights": (1.0, 2.0)}, code_version="x", wall_time_s=1.5,
        warnings=("w",),
    )
    assert r.config["heights"] == [1.0, 2.0]  # kept as JSON reads it back
    path = write_result(tmp_path, r)
    assert read_result(path) == r
    located = replace(r, facades=(FacadeEstimate(id=1, wwr=0.3, normal=(0.0, -1.0, 0.0),
                                                 centre_m=(1.5, -2.0, 4.25)),))
    assert read_result(write_result(tmp_path, located)) == located
    path.write_text("{not json")
    with pytest.raises(ValueError, match="not a valid result"):
        read_result(path)


def test_result_file_without_facade_geometry_still_loads(tmp_path):
    """Files written before FacadeEstimate had ``normal`` and ``centre_m``."""
    old = {"scene": "s", "method": "2D-S", "protocol": "ideal", "wwr": 0.3,
           "window_area_m2": None, "facade_area_m2": None,
           "facades": [{"id": 1, "wwr": 0.3, "window_area_m2": None, "facade_area_m2": None,
                        "width_m": None, "height_m": None, "views_used": 2,
                        "missing": False, "reason": ""}]}
    path = tmp_path / "old.json"
    path.write_text(json.dumps(old))
    facade = read_result(path).facades[0]
    assert (facade.views_used, facade.normal, facade.centre_m) == (2, None, None)


def test_footprint_geojson_round_trip():
    from shapely.geometry import Polygon

    from envelope.footprint import geojson_to_polygon, polygon_to_geojson

    ring = [(0, 0), (0, 4), (3, 4), (3, 0)]  # clockwise on purpose
    hole = [(1, 1), (2, 1), (2, 2), (1, 2)]
    poly = Polygon(ring, [hole])
    geo = polygon_to_geojson(poly)
    assert geo["type"] == "Polygon"
    back = geojson_to_polygon(geo)
    assert back.area == pytest.approx(11.0)
    assert back.symmetric_difference(poly).area < 1e-12
    assert Polygon(geo["coordinates"][0]).exterior.is_ccw
    with pytest.raises(ValueError, match="GeoJSON Polygon"):
        geojson_to_polygon({"type": "Point", "coordinates": [0, 0]})


def test_facade_outlines_are_a_typed_field_and_old_files_still_read(tmp_path):
    from metrics_helpers import make_truth

    from envelope.truth import BuildingTruth, read_building, write_building

    outline = [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [4.0, 0.0, 3.0], [0.0, 0.0, 3.0]]
    truth = replace(make_truth("a"), facade_outlines_m={1: [outline]})
    assert truth.facade_outlines_m[1][0][2] == (4.0, 0.0, 3.0)
    write_building(tmp_path / "building.json", truth)
    assert read_building(tmp_path / "building.json") == truth
    old = truth.to_json_dict()
    old["extra"] = {"facade_outlines_m": old.pop("facade_outlines_m")}
    assert BuildingTruth.from_json_dict(old) == truth
