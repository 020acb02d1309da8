"""baselines.wwr2ds: 2D-S on closed-form facade views, its result file and its CLI."""

import json
from dataclasses import replace

import numpy as np
import pytest
from baselines_synthetic import facade_pose, render_facade, window_grid, write_facade_scene

from baselines.views import FacadeView
from baselines.wwr2ds import Wwr2dsConfig, main, measure_view_2ds, run_2ds
from envelope.camera import Intrinsics
from envelope.classes import SemanticClass
from envelope.results import read_result
from envelope.scene_record import Frame
from envelope.scenes.scene import read_method_input, write_transforms

L_M, H_M = 12.0, 9.0
WINDOWS = window_grid(L_M, H_M, 4, 3, 1.6, 1.5)
FACADE = dict(length_m=L_M, height_m=H_M, windows=WINDOWS)
K = Intrinsics.from_fov(200, 160, 60.0)


def _view(pose, k=K, **extra):
    labels, depth = render_facade(k, pose, **{**FACADE, **extra})
    return FacadeView("s", 1, 0, Frame("x.png", pose, k, "ideal", facade_id=1), labels, depth)


def test_perpendicular_view_gives_the_exact_pixel_ratio_and_scale():
    # Camera at mid-height looking straight at the facade: every facade pixel
    # is at z = 16 m, so the pixel footprint (z/f)² is exact for all of them.
    pose = facade_pose(L_M, H_M, distance_m=16.0, azimuth_deg=0.0, eye_height_m=H_M / 2)
    view = _view(pose)
    m, warning = measure_view_2ds(view, Wwr2dsConfig())
    window = (view.labels == SemanticClass.WINDOW).sum()
    facade = np.isin(view.labels, [1, 2, 4]).sum()
    assert warning is None
    assert m.wwr == window / facade  # exactly the pixel ratio
    assert m.wwr == pytest.approx(12 * 1.6 * 1.5 / (L_M * H_M), abs=0.01)  # pixelisation
    np.testing.assert_allclose(np.median(view.depth_z_m[m.mask]), 16.0, rtol=1e-9)
    assert m.facade_area_m2 == pytest.approx(facade * (16.0 / K.fx) ** 2, rel=1e-9)
    assert m.facade_area_m2 == pytest.approx(L_M * H_M, rel=0.02)


def test_oblique_view_keeps_the_inconsistent_scale_on_purpose():
    pose = facade_pose(L_M, H_M, distance_m=16.0, azimuth_deg=45.0)
    m, _ = measure_view_2ds(_view(pose), Wwr2dsConfig())
    assert m.facade_area_m2 < 0.85 * L_M * H_M  # one (z/f)² per view: foreshortening stays


def test_no_depth_keeps_the_wwr_and_drops_the_areas():
    view = replace(_view(facade_pose(L_M, H_M, distance_m=16.0, azimuth_deg=0.0)),
                   depth_z_m=np.zeros((K.height, K.width)))
    m, warning = measure_view_2ds(view, Wwr2dsConfig())
    assert m.wwr > 0.2 and m.facade_area_m2 is None
    assert "no valid depth on the facade" in warning


def _scene(tmp_path):
    poses = [(1, facade_pose(L_M, H_M, distance_m=16.0, azimuth_deg=0.0)),
             (2, facade_pose(L_M, H_M, distance_m=16.0, azimuth_deg=30.0)),
             (2, facade_pose(L_M, H_M, distance_m=18.0, azimuth_deg=-30.0)),
             (3, facade_pose(L_M, H_M, distance_m=16.0, azimuth_deg=0.0))]
    s = write_facade_scene(tmp_path / "bench" / "facade_scene", poses, K, **FACADE)
    frames = list(s.frames)
    frames[3] = replace(frames[3], semantic_file_path=None)
    write_transforms(s.root, replace(s, frames=tuple(frames)))
    return read_method_input(s.root)


def test_run_averages_views_then_facades_and_reports_missing(tmp_path):
    r = run_2ds(_scene(tmp_path), "ideal", debug_dir=tmp_path / "dbg")
    assert (r.method, r.protocol, r.scene) == ("2D-S", "ideal", "facade_scene")
    f1, f2, f3 = r.facades
    assert (f1.views_used, f2.views_used, f3.missing) == (1, 2, True)
    assert "no semantic_file_path" in f3.reason
    assert r.wwr == pytest.approx((f1.wwr + f2.wwr) / 2)  # unweighted over facades present
    assert r.facade_area_m2 == pytest.approx(f1.facade_area_m2 + f2.facade_area_m2)
    assert any("skipped" in w and "no semantic_file_path" in w for w in r.warnings)
    assert (tmp_path / "dbg" / "facade_scene__ideal__f2__v1__mask.png").is_file()
    assert {k: r.config[k] for k in ("isolation", "combine")} == {
        "isolation": "centre_component", "combine": "mean"}
    assert r.config["own_facades"]["cells"]["cell_m"] == Wwr2dsConfig().own_facades.cells.cell_m


def test_cli_writes_one_result_per_scene(tmp_path, capsys):
    scene = _scene(tmp_path)
    assert main(["--views", "ideal", "--data", str(scene.root.parent)]) == 0
    out = tmp_path / "bench-results" / "facade_scene__2D-S__ideal.json"  # <data>-results
    assert read_result(out).method == "2D-S"
    assert json.loads(out.read_text())["facades"][2]["missing"] is True
    assert "warning:" in capsys.readouterr().err


def test_cli_user_mistakes_are_one_line_and_exit_2(tmp_path, capsys):
    assert main(["--views", "ideal", "--data", str(tmp_path / "nowhere")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "does not exist" in err
    scene = _scene(tmp_path)
    assert main(["--views", "multi", "--data", str(scene.root), "--out", str(tmp_path)]) == 2
    assert "has no multi views" in capsys.readouterr().err
    assert not list(tmp_path.glob("*.json"))
