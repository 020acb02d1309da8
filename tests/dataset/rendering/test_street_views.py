"""Street views: stations along a street and round a block against closed forms, the poses'
axes, the ``street`` split in a scene folder, and (slow, on the lod3 preset) cameras that do
not depend on the truth and roads that run between the buildings."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest
import shapely
from conftest import assert_complete_scene, make_box_building
from shapely.geometry import Polygon, box

from dataset.rendering.street_views import (
    StreetConfig,
    street_pose,
    street_stations,
    street_views,
)
from dataset.scenes.scene_writer import GenerateConfig, generate_scene, plan_views
from envelope.geometry.raycast import Raycaster
from envelope.mesh import LabelledMesh
from envelope.neighbours import Neighbour, Street

BOX_XY = box(-10.0, -6.0, 10.0, 6.0)  # conftest's box building seen from above
PITCH = np.radians(20.0)


def _street_along_x(y_m: float, x_m: float = 50.0) -> Street:
    return Street("test", np.array([[-x_m, y_m, 0.0], [x_m, y_m, 0.0]]))


def _shifted(mesh: LabelledMesh, dx_m: float, dy_m: float = 0.0) -> LabelledMesh:
    return LabelledMesh(mesh.vertices_m + [dx_m, dy_m, 0.0], mesh.faces, mesh.face_label,
                        mesh.face_facade)


def test_straight_street_stations_and_frames():
    building = replace(make_box_building(), streets=(_street_along_x(-15.0),))
    config = StreetConfig()
    stations = street_stations(building, config)
    # every 5 m from x = -50; within 40 m of the box: |x| - 10 <= sqrt(40^2 - 9^2) = 38.97
    np.testing.assert_allclose(stations.positions_m[:, 0], np.arange(-45.0, 46.0, 5.0))
    np.testing.assert_allclose(stations.positions_m[:, 1:], [[-15.0, 2.5]] * 19)
    np.testing.assert_allclose(stations.forward, [[1.0, 0.0]] * 19)
    poses = street_views(building, config, context=False)
    looks = np.array([-p[:3, 2] for p in poses])
    assert len(poses) > 0 and (looks[:, 1] > 0).all()  # only frames towards the building
    square_on = [p for p in poses if np.allclose(p[:3, 3], [0.0, -15.0, 2.5])
                 and np.allclose(-p[:3, 2], [0.0, np.cos(PITCH), np.sin(PITCH)])]
    assert len(square_on) == 1
    far = StreetConfig(capture_range_m=8.0)  # no station within 8 m of the box
    assert street_views(building, far, context=False) == []


def test_street_pose_axes():
    pose = street_pose(np.array([1.0, 2.0, 2.5]), np.array([0.6, 0.8]), -90.0, 20.0)
    look = -pose[:3, 2]
    np.testing.assert_allclose(look, [0.8 * np.cos(PITCH), -0.6 * np.cos(PITCH),
                                      np.sin(PITCH)], atol=1e-12)  # right of the direction
    np.testing.assert_allclose(pose[:3, :3].T @ pose[:3, :3], np.eye(3), atol=1e-12)
    assert np.linalg.det(pose[:3, :3]) == pytest.approx(1.0)
    assert pose[2, 0] == 0.0 and pose[2, 1] > 0  # image x level, image y up


def test_no_road_network_drives_round_the_block():
    building = make_box_building()
    stations = street_stations(building, StreetConfig())
    distance = shapely.distance(BOX_XY, shapely.points(stations.positions_m[:, :2]))
    np.testing.assert_allclose(distance, 6.0, atol=2e-3)
    # stations every 5 m round a ring of perimeter 2 (20 + 12) + 2 pi 6; the last one,
    # closer than 2.5 m to the first, is dropped
    perimeter = 64.0 + 12.0 * np.pi
    expected = int(np.floor(perimeter / 5.0)) + 1 - (perimeter % 5.0 < 2.5)
    assert len(stations.positions_m) == expected
    # a neighbour 1 m away (a party-wall gap) joins the block; the path goes round both
    other = _shifted(building.mesh, 21.0)
    pair = replace(building, context=(Neighbour("east", other),))
    ring = street_stations(pair, StreetConfig(capture_range_m=100.0)).positions_m
    block = shapely.union_all([BOX_XY, box(11.0, -6.0, 31.0, 6.0)]).buffer(0.5)
    np.testing.assert_allclose(shapely.distance(block, shapely.points(ring[:, :2])), 6.0 - 0.5,
                               atol=2e-3)
    assert ring[:, 0].max() > 31.0


def test_stations_under_a_neighbour_are_dropped():
    """A path through a house (its roof over the camera) gives no frame there."""
    building = replace(make_box_building(), streets=(_street_along_x(-15.0),))
    across = Neighbour("across", _shifted(building.mesh, 0.0, -17.0))  # y from -23 to -11
    with_house = replace(building, context=(across,))
    poses = street_views(with_house, StreetConfig(), context=True)
    xs = {round(float(p[0, 3]), 6) for p in poses}
    assert xs and all(abs(x) > 10.0 for x in xs)  # under the house for |x| <= 10


def test_scene_with_street_frames(tmp_path):
    building = replace(make_box_building(), streets=(_street_along_x(-15.0),))
    street = StreetConfig(check_resolution=16)
    config = GenerateConfig(resolution=24, views=2, multi=False, street=street)
    plain = replace(config, street=None)
    planned = plan_views(building, Raycaster(building.mesh), config, seed=3)
    before = plan_views(building, Raycaster(building.mesh), plain, seed=3)
    # the other views are those of a scene without street frames, street frames after them
    assert [v.name for v in planned[:len(before)]] == [v.name for v in before]
    for a, b in zip(planned, before):
        np.testing.assert_array_equal(a.world_from_camera, b.world_from_camera)
    assert {v.split for v in planned[len(before):]} == {"street"}
    root = generate_scene(building, tmp_path, config, seed=3, progress=False)
    assert_complete_scene(root, config)
    meta = json.loads((root / "transforms.json").read_text())
    frames = [f for f in meta["frames"] if f["split"] == "street"]
    assert len(frames) == len(planned) - len(before)
    assert all("facade_id" not in f for f in frames)
    assert frames[0]["fl_x"] == pytest.approx(12.0)  # 90 degrees over 24 pixels
    assert meta["generator"]["config"]["street"]["spacing_m"] == 5.0
    other = generate_scene(building, tmp_path / "plain", plain, seed=3, progress=False)
    assert "street" not in json.loads((other / "transforms.json").read_text())[
        "generator"]["config"]  # a scene without street frames records what it always did


@pytest.fixture(scope="module")
def lod3_building():
    from dataset.importers.citygml.preset import build_lod3_building, lod3_entries

    entry = next(e for e in lod3_entries() if e.id == "4018106")
    return build_lod3_building(entry.id, entry.file)


@pytest.mark.slow
def test_street_cameras_do_not_read_the_truth(lod3_building):
    building = lod3_building
    assert len(building.streets) > 100
    config = StreetConfig()
    poses = street_views(building, config, context=True)
    assert len(poses) >= 20
    truth = building.truth
    rng = np.random.default_rng(0)
    poisoned_truth = replace(truth, id="poisoned", wwr=0.9, window_area_m2=1.0, extra={},
                             facades=tuple(replace(f, id=f.id + 10, window_area_m2=0.0,
                                                   normal=(0.0, 0.0, 1.0))
                                           for f in reversed(truth.facades)))
    mesh = building.mesh
    poisoned_mesh = LabelledMesh(mesh.vertices_m, mesh.faces,
                                 rng.integers(0, 6, len(mesh.faces)),
                                 rng.integers(0, 9, len(mesh.faces)))
    poisoned = replace(building, truth=poisoned_truth, mesh=poisoned_mesh)
    again = street_views(poisoned, config, context=True)
    assert len(again) == len(poses)
    for a, b in zip(poses, again):
        np.testing.assert_array_equal(a, b)


@pytest.mark.slow
def test_committed_roads_run_between_the_buildings():
    """The lanes of the committed OpenDRIVE file, mapped as the buildings are, cross no
    building's ground surface and pass within 30 m of every scene building."""
    from dataset.importers.citygml.preset import ROAD_NETWORK, lod3_entries, lod3_files
    from dataset.importers.citygml.read import read_citygml
    from dataset.importers.opendrive.streets import streets_in_frame

    lanes = shapely.MultiLineString([s.points_m[:, :2] for s in streets_in_frame(
        ROAD_NETWORK, "EPSG:32632", (0.0, 0.0, 0.0))])
    scene = {(e.file, e.gml_id) for e in lod3_entries()}
    far, crossed, count = [], [], 0
    for f in lod3_files():
        for b in read_citygml(f.path).buildings:
            ground = [shapely.make_valid(Polygon(p.rings_m[0][:, :2])) for p in b.polygons
                      if p.kind == "ground"]
            if not ground:
                continue
            footprint = shapely.union_all(ground)
            if lanes.intersects(footprint):
                crossed.append(b.gml_id)
            key = (f.path.relative_to(f.path.parents[1]).as_posix(), b.gml_id)
            if key in scene:
                count += 1
                if lanes.distance(footprint) > 30.0:
                    far.append(b.gml_id)
    assert count == len(scene) and not crossed and not far


def test_bad_settings_are_refused():
    with pytest.raises(ValueError, match="camera_height_m"):
        StreetConfig(camera_height_m=12.0)
    with pytest.raises(ValueError, match="headings_deg"):
        StreetConfig(headings_deg=())
    with pytest.raises(ValueError, match="N >= 2"):
        Street("one point", np.zeros((1, 3)))
