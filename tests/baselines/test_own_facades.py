"""2D-SS and 2D-S on views without facade ids find the facades themselves
(baselines.own_facades), checked against the truth by the one scoring rule
(metrics.score.errors)."""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
import pytest
from baselines_synthetic import facade_pose, true_wwr, window_grid, write_facade_scene
from conftest import make_box_building

from baselines import wwr2ds, wwr2dss
from baselines.facade_cells import measure_facades
from baselines.own_facades import OwnFacadesConfig, find_own_facades
from baselines.plane_merge import merge_view_planes
from baselines.posed_views import PosedView
from baselines.view_planes import find_view_planes
from baselines.wwr2ds import Wwr2dsConfig, run_2ds
from baselines.wwr2dss import Wwr2dssConfig, run_2dss
from dataset.generate import GenerateConfig
from dataset.presets import build_building, preset_recipes
from dataset.rendering.render import render_ground_truth
from dataset.scenes.scene_writer import generate_scene
from envelope.camera import Intrinsics, look_at
from envelope.classes import SemanticClass
from envelope.results import read_result
from envelope.scene_record import Frame
from envelope.scenes.images import read_depth_m, read_labels, write_depth_m, write_labels
from envelope.scenes.scene import read_method_input, read_scene, write_transforms
from envelope.truth import Building
from metrics.score.errors import building_errors, facade_errors

K = Intrinsics.from_fov(160, 120, 60.0)
L_M, H_M = 10.0, 6.0
WINDOWS = window_grid(L_M, H_M, cols=3, rows=2, width_m=1.2, win_height_m=1.4)
NORMAL_DEG = 2.0  # a facade's normal within this of its wall's
AREA_REL = 0.03  # 2D-SS facade area within 3 % of the truth's
WWR_POINTS = 2.0  # 2D-SS and 2D-S facade WWR within 2 points of the truth's
ORBIT = GenerateConfig(resolution=128, views=32, ideal=False, multi=False)  # 16 train views


def _synthetic_scene(tmp_path):
    """Three views of the facade, one of the sky, one without a semantic mask, one whose mask
    shows a 5 x 5 px patch of wall (too little for a plane); no facade ids."""
    poses = [facade_pose(L_M, H_M, distance_m=16.0, azimuth_deg=a) for a in (-25.0, 0.0, 25.0)]
    poses.append(look_at([L_M / 2, -16.0, 1.6], [L_M / 2, -16.0 + 1.0, 40.0]))  # the sky
    poses += [poses[1], poses[1]]
    s = write_facade_scene(tmp_path / "facade_scene", [(None, p) for p in poses], K,
                           split="train", length_m=L_M, height_m=H_M, windows=WINDOWS)
    frames = list(s.frames)
    frames[4] = replace(frames[4], semantic_file_path=None)
    patch = np.zeros((K.height, K.width), dtype=np.uint8)
    patch[60:65, 80:85] = SemanticClass.WALL
    write_labels(s.path(frames[5].semantic_file_path), patch)
    write_transforms(s.root, replace(s, frames=tuple(frames)))
    return read_method_input(s.root)


def test_2dss_finds_the_one_facade_and_skips_views_with_nothing_usable(tmp_path):
    r = run_2dss(_synthetic_scene(tmp_path), "train")
    assert (r.protocol, r.facade_identity) == ("train", "geometry")
    (f,) = r.facades
    assert f.id == 1 and f.views_used == 3
    np.testing.assert_allclose(f.normal, [0.0, -1.0, 0.0], atol=np.radians(NORMAL_DEG))
    np.testing.assert_allclose(f.centre_m, [L_M / 2, 0.0, H_M / 2], atol=0.1)
    assert f.facade_area_m2 == pytest.approx(L_M * H_M, rel=AREA_REL)
    assert 100 * abs(f.wwr - true_wwr(L_M, H_M, WINDOWS)) < WWR_POINTS
    assert (r.wwr, r.facade_area_m2) == (f.wwr, f.facade_area_m2)
    skipped = [w for w in r.warnings if "skipped" in w]
    assert len(skipped) == 3
    assert any("train_003" in w and "no wall, window or door pixel" in w for w in skipped)
    assert any("train_004" in w and "no semantic_file_path" in w for w in skipped)
    assert any("train_005" in w and "no vertical facade plane" in w for w in skipped)


def test_2ds_groups_the_views_of_one_facade(tmp_path):
    r = run_2ds(_synthetic_scene(tmp_path), "train")
    (f,) = r.facades
    assert r.facade_identity == "geometry" and f.views_used == 3
    np.testing.assert_allclose(f.normal, [0.0, -1.0, 0.0], atol=np.radians(NORMAL_DEG))
    assert 100 * abs(f.wwr - true_wwr(L_M, H_M, WINDOWS)) < WWR_POINTS


def test_a_split_without_usable_views_fails_with_the_reasons(tmp_path):
    scene = _synthetic_scene(tmp_path)
    sky_only = replace(scene, frames=tuple(
        f for f in scene.frames if f.file_path.endswith(("003.png", "004.png", "005.png"))))
    with pytest.raises(ValueError, match="nothing left to measure.*no wall, window or door"):
        run_2dss(sky_only, "train")


def _orbit_scene(building: Building, folder):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return generate_scene(building, folder, ORBIT, seed=0, progress=False)


@pytest.fixture(scope="module")
def box_scene(tmp_path_factory):
    return _orbit_scene(make_box_building(), tmp_path_factory.mktemp("box_orbit"))


@pytest.mark.slow
def test_2dss_on_orbit_views_finds_each_wall_of_the_box_once(box_scene):
    truth = read_scene(box_scene).building
    r = run_2dss(read_method_input(box_scene), "train")
    rows = facade_errors(r, truth)
    assert [x.kind for x in rows] == ["matched"] * 4  # one estimate per wall, none elsewhere
    azimuths = [np.degrees(np.arctan2(f.normal[1], f.normal[0])) % 360 for f in r.facades]
    assert azimuths == sorted(azimuths) and [f.id for f in r.facades] == [1, 2, 3, 4]
    by_normal = {tuple(np.round(f.normal)): f for f in r.facades}
    for wall in truth.facades:
        est = by_normal[tuple(np.round(wall.normal))]
        angle = np.degrees(np.arccos(np.clip(np.dot(est.normal, wall.normal), -1, 1)))
        assert angle < NORMAL_DEG
        assert est.facade_area_m2 == pytest.approx(wall.facade_area_m2, rel=AREA_REL)
        assert 100 * abs(est.wwr - wall.wwr) < WWR_POINTS
    b = building_errors(r, truth)
    assert b.facade_ape < 100 * AREA_REL and 100 * abs(b.wwr_est - b.wwr_true) < WWR_POINTS


@pytest.mark.slow
def test_2ds_on_orbit_views_groups_every_view_into_one_of_the_walls(box_scene):
    truth = read_scene(box_scene).building
    scene = read_method_input(box_scene)
    r = run_2ds(scene, "train", Wwr2dsConfig())
    assert [x.kind for x in facade_errors(r, truth)] == ["matched"] * 4
    found = find_own_facades(scene, "train", Wwr2dsConfig().own_facades, seed=0)
    assert sum(f.views_used for f in r.facades) == len(found.loaded.views)
    assert all(x.wwr_points < WWR_POINTS for x in facade_errors(r, truth))


@pytest.mark.slow
def test_the_two_parallel_walls_of_the_l_shape_are_two_facades(tmp_path):
    # The tiny L-shape's +x walls lie 5 m apart; each is its own facade, on its own wall.
    recipe = next(r for r in preset_recipes("tiny") if r.id == "tiny_l_shaped")
    root = _orbit_scene(build_building(recipe), tmp_path)
    truth = read_scene(root).building
    r = run_2dss(read_method_input(root), "train", Wwr2dssConfig())
    plus_x = [f for f in r.facades if f.normal[0] > np.cos(np.radians(NORMAL_DEG))]
    assert len(plus_x) == 2
    assert abs(plus_x[0].centre_m[0] - plus_x[1].centre_m[0]) > 1.0
    rows = facade_errors(r, truth)
    walls = [t.id for t in truth.facades if t.normal[0] > 0.99]
    assert len(walls) == 2 and all(x.kind == "matched" for x in rows if x.facade_id in walls)
    assert not [x for x in rows if x.kind == "false_positive"]


@pytest.mark.slow
def test_street_views_along_the_box_find_the_walls_they_see(box_building):
    # 33 photos from the pavement (eye height, 18 m in front of the -y wall, x from -25 to
    # 25 m, looking ahead and 30 degrees to either side): the -y wall and both side walls,
    # each measured once although most photos show two of them; the +y wall is never seen.
    k = Intrinsics.from_fov(256, 192, 70.0)
    views = []
    for x in np.linspace(-25.0, 25.0, 11):
        for yaw in np.radians([-30.0, 0.0, 30.0]):
            eye = np.array([x, -18.0, 1.6])
            pose = look_at(eye, eye + [10 * np.sin(yaw), 10 * np.cos(yaw), 2.0])
            gt = render_ground_truth(box_building.mesh, k, pose)
            views.append(PosedView("street", len(views), Frame(f"v{len(views)}.png", pose, k,
                                                               "train"),
                                   gt.labels, gt.depth_z_m.astype(np.float32)))
    config = OwnFacadesConfig()
    planes = [p for v in views if v.facade_pixels().any()
              for p in find_view_planes(v, config.fit, np.random.default_rng(v.index))]
    facades = merge_view_planes(planes, config.merge)
    measured = measure_facades(facades, views, config.cells)
    assert len(facades) == 3
    for facade, cells in zip(facades, measured):
        wall = max(box_building.truth.facades, key=lambda t: np.dot(t.normal, facade.normal))
        assert np.degrees(np.arccos(min(1.0, np.dot(wall.normal, facade.normal)))) < NORMAL_DEG
        assert cells.areas.gross_m2 == pytest.approx(wall.facade_area_m2, rel=AREA_REL)
        assert 100 * abs(cells.areas.wwr - wall.wwr) < WWR_POINTS


def test_views_whose_depth_covers_under_half_the_building_are_used(tmp_path):
    """A photos scene's depth comes from sparse points and covers part of each photo
    (docs/importing.md, section 9): holes are pixels without depth, not a scene error."""
    scene = _synthetic_scene(tmp_path)
    for frame in scene.frames[:3]:
        depth = read_depth_m(scene.path(frame.depth_file_path), scene.depth_unit_scale_factor)
        building = read_labels(scene.path(frame.semantic_file_path)) != SemanticClass.BACKGROUND
        depth[:, : int(0.6 * K.width)] = 0.0
        assert (building & (depth == 0)).sum() > 0.5 * building.sum()
        write_depth_m(scene.path(frame.depth_file_path), depth, scene.depth_unit_scale_factor)
    (f,) = run_2dss(read_method_input(scene.root), "train").facades
    assert f.views_used == 3
    np.testing.assert_allclose(f.normal, [0.0, -1.0, 0.0], atol=np.radians(NORMAL_DEG))


def test_the_command_lines_run_on_train_views(tmp_path, capsys):
    """``--views train``: a photos scene's photos are ``train`` frames (docs/importing.md,
    section 9); the result file is the one ``metrics.compare`` would name."""
    scene = _synthetic_scene(tmp_path)
    out = tmp_path / "results"
    for cli, method in ((wwr2dss, "2D-SS"), (wwr2ds, "2D-S")):
        assert cli.main(["--views", "train", "--data", str(scene.root), "--out", str(out)]) == 0
        result = read_result(out / f"{scene.root.name}__{method}__train.json")
        assert (result.protocol, result.facade_identity, len(result.facades)) == (
            "train", "geometry", 1)
    assert "2D-SS train: building WWR" in capsys.readouterr().out
