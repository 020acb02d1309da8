"""Scene generation: folders load back, resumable preset runs, atomicity, the CLI's messages."""

import json
import sys
import types
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from conftest import TINY_CONFIG, make_box_building

import dataset.generate as generate
from dataset.camera import look_at
from dataset.cameras import OrbitConfig
from dataset.cameras import sample_orbit_views as real_sample_orbit_views
from dataset.generate import (
    GenerateConfig,
    depth_unit_for,
    generate_preset,
    generate_scene,
    main,
    scene_is_finished,
)
from dataset.images import read_depth_m, read_facade_ids, read_labels, read_normals, read_rgb
from dataset.mesh import read_labelled_ply
from dataset.render import Raycaster, render_ground_truth
from dataset.scene import read_scene
from dataset.truth import Building

SMALL = GenerateConfig(resolution=40, views=6)


def _assert_complete_scene(root: Path, config: GenerateConfig) -> None:
    scene = read_scene(root)
    assert scene.building is not None
    for frame in scene.frames:
        for rel in (frame.file_path, frame.depth_file_path, frame.semantic_file_path,
                    frame.normal_file_path, frame.instance_file_path):
            assert rel is not None and scene.path(rel).is_file(), rel
        assert (frame.facade_id is not None) == (frame.split in ("ideal", "multi"))
        assert frame.intrinsics == config.intrinsics()
    n_train = len(scene.frames_in("train"))
    assert n_train + len(scene.frames_in("eval")) == config.views
    assert n_train == int(np.floor(config.views * config.train_fraction))
    assert not list(root.parent.glob(".*.partial"))


def test_generated_scene_loads_back_exactly(tmp_path):
    box = make_box_building()
    root = generate_scene(box, tmp_path, SMALL, seed=3, progress=False)
    assert root == tmp_path / "box"
    _assert_complete_scene(root, SMALL)
    scene = read_scene(root)
    assert len(scene.frames_in("ideal")) == 4 and len(scene.frames_in("multi")) == 20
    assert scene.building == box.truth
    mesh = read_labelled_ply(root / "mesh.ply")
    np.testing.assert_array_equal(mesh.face_facade, box.mesh.face_facade)
    # Files hold exactly what the renderer gives for the recorded pose.
    rc = Raycaster(box.mesh)
    for frame in scene.frames_in("ideal")[:1] + scene.frames_in("train")[:1]:
        gt = render_ground_truth(rc, frame.intrinsics, frame.world_from_camera)
        depth = read_depth_m(scene.path(frame.depth_file_path), scene.depth_unit_scale_factor)
        np.testing.assert_allclose(depth, gt.depth_z_m, atol=scene.depth_unit_scale_factor / 2)
        np.testing.assert_array_equal(read_labels(scene.path(frame.semantic_file_path)), gt.labels)
        ids = read_facade_ids(scene.path(frame.instance_file_path))
        np.testing.assert_array_equal(ids, gt.facade_ids)
        normals = read_normals(scene.path(frame.normal_file_path))
        np.testing.assert_allclose(normals, gt.normals_world, atol=1e-4)
        assert read_rgb(scene.path(frame.file_path)).shape == (40, 40, 3)
    ideal = scene.frames_in("ideal")[0]
    assert read_facade_ids(scene.path(ideal.instance_file_path))[20, 20] == ideal.facade_id
    assert scene_is_finished(root, SMALL, seed=3)
    assert not scene_is_finished(root, SMALL, seed=4)
    assert not scene_is_finished(root, replace(SMALL, resolution=41), seed=3)


def test_tiny_benchmark_fixture_is_complete(tiny_benchmark):
    names = sorted(p.name for p in tiny_benchmark.iterdir())
    assert names == ["realistic_house", "tiny_l_shaped", "tiny_skyscraper"]
    for root in tiny_benchmark.iterdir():
        _assert_complete_scene(root, TINY_CONFIG)
        scene = read_scene(root)
        assert scene.frames_in("ideal") and scene.frames_in("multi")
        facades = {f.id for f in scene.building.facades}
        assert {f.facade_id for f in scene.frames_in("ideal")} <= facades


def test_depth_unit_grows_only_when_views_reach_past_16_bits():
    rc = Raycaster(make_box_building().mesh)
    near = look_at([0.0, -40.0, 5.0], [0.0, 0.0, 4.5])
    far = look_at([0.0, -100.0, 5.0], [0.0, 0.0, 4.5])  # farthest corner ~106 m
    assert depth_unit_for(0.001, rc, [near]) == 0.001
    assert depth_unit_for(0.001, rc, [near, far]) == pytest.approx(0.002)
    assert depth_unit_for(0.01, rc, [far]) == 0.01


def _fake_presets(monkeypatch, calls: list):
    """A stand-in ``dataset.presets`` with two box buildings (keeps these tests fast)."""
    fake = types.ModuleType("dataset.presets")
    fake.PRESETS = ("boxes",)

    def preset_recipes(name):
        if name != "boxes":
            raise ValueError(f"unknown preset {name!r}")
        return (types.SimpleNamespace(id="box_a", seed=1),
                types.SimpleNamespace(id="box_b", seed=2))

    def build_building(recipe):
        calls.append(recipe.id)
        box = make_box_building()
        return Building(box.mesh, replace(box.truth, id=recipe.id))

    fake.preset_recipes, fake.build_building = preset_recipes, build_building
    monkeypatch.setitem(sys.modules, "dataset.presets", fake)


def test_preset_run_is_resumable(tmp_path, monkeypatch):
    calls: list = []
    _fake_presets(monkeypatch, calls)
    scenes = generate_preset("boxes", tmp_path, SMALL, progress=False)
    assert [s.name for s in scenes] == ["box_a", "box_b"] and calls == ["box_a", "box_b"]
    for s in scenes:
        _assert_complete_scene(s, SMALL)
    # A killed run's leftovers are cleared; finished scenes are skipped.
    (tmp_path / ".box_b.x1.partial").mkdir()
    stamp = (tmp_path / "box_a" / "transforms.json").stat().st_mtime_ns
    generate_preset("boxes", tmp_path, SMALL, progress=False)
    assert calls == ["box_a", "box_b"]
    assert (tmp_path / "box_a" / "transforms.json").stat().st_mtime_ns == stamp
    assert not (tmp_path / ".box_b.x1.partial").exists()
    # Another config never silently mixes into the folder.
    other = replace(SMALL, views=4)
    with pytest.raises(ValueError, match="another config or seed"):
        generate_preset("boxes", tmp_path, other, progress=False)
    generate_preset("boxes", tmp_path, other, overwrite=True, progress=False)
    _assert_complete_scene(tmp_path / "box_a", other)
    with pytest.raises(ValueError, match="unknown preset"):
        generate_preset("nope", tmp_path, SMALL, progress=False)
    with pytest.raises(ValueError, match="workers"):
        generate_preset("boxes", tmp_path, SMALL, workers=0, progress=False)


def test_interrupted_scene_leaves_nothing_behind(tmp_path, monkeypatch):
    real = generate._render_view
    count = {"n": 0}

    def interrupt_on_third(*args, **kwargs):
        count["n"] += 1
        if count["n"] == 3:
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    monkeypatch.setattr(generate, "_render_view", interrupt_on_third)
    with pytest.raises(KeyboardInterrupt):
        generate_scene(make_box_building(), tmp_path, SMALL, seed=0, progress=False)
    assert list(tmp_path.iterdir()) == []


@pytest.fixture()
def box_ply() -> Path:
    """The importer's closed example mesh (building id ``example_bim``)."""
    return Path(__file__).resolve().parents[1] / "dataset" / "examples" / "example_bim.ply"


def test_cli_generates_a_users_mesh_and_resumes(tmp_path, box_ply, capsys):
    out = tmp_path / "out"
    args = ["--mesh", str(box_ply), "--out", str(out), "--resolution", "32", "--views", "4",
            "--quiet"]
    assert main(args) == 0
    scene = out / "example_bim"
    _assert_complete_scene(scene, GenerateConfig(resolution=32, views=4))
    assert capsys.readouterr().out.strip() == str(scene)
    stamp = (scene / "transforms.json").stat().st_mtime_ns
    assert main(args) == 0
    assert (scene / "transforms.json").stat().st_mtime_ns == stamp


def _one_line_error(capsys) -> str:
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err
    return err


def test_cli_bad_inputs_give_one_line_and_exit_code(tmp_path, box_ply, capsys):
    blocker = tmp_path / "a_file"
    blocker.write_text("not a folder")
    assert main(["--mesh", str(box_ply), "--out", str(blocker / "sub"), "--quiet"]) == 2
    assert _one_line_error(capsys).startswith("error: cannot write to output folder")
    assert main(["--mesh", str(tmp_path / "missing.ply"), "--out", str(tmp_path)]) == 2
    assert "missing.ply" in _one_line_error(capsys)
    assert main(["--mesh", str(box_ply), "--out", str(tmp_path / "o"), "--views", "0"]) == 2
    assert "views must be >= 1" in _one_line_error(capsys)
    with pytest.raises(SystemExit) as exit_info:
        main(["--out", str(tmp_path)])  # neither --preset nor --mesh: argparse usage error
    assert exit_info.value.code == 2


def test_cli_unframeable_mesh_and_ctrl_c(tmp_path, box_ply, capsys, monkeypatch):
    def impossible(building, raycaster, intrinsics, n, *, config, seed):
        strict = OrbitConfig(min_coverage=0.95, max_attempts=2, max_adjustments=1)
        return real_sample_orbit_views(building, raycaster, intrinsics, n, config=strict,
                                       seed=seed)

    out = tmp_path / "out"
    args = ["--mesh", str(box_ply), "--out", str(out), "--resolution", "32", "--views", "2",
            "--quiet"]
    with monkeypatch.context() as m:
        m.setattr(generate, "sample_orbit_views", impossible)
        assert main(args) == 2
    assert "cannot frame building 'example_bim'" in _one_line_error(capsys)
    assert not (out / "example_bim").exists()

    def ctrl_c(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(generate, "_render_view", ctrl_c)
    assert main(args) == 130
    assert _one_line_error(capsys).startswith("interrupted")
    assert [p.name for p in out.iterdir()] == []


def test_cli_help_explains_the_options(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["--help"])
    assert exit_info.value.code == 0
    text = capsys.readouterr().out
    for option in ("--preset", "--mesh", "--out", "--resolution", "--views", "--workers",
                   "--seed", "resume"):
        assert option in text


def test_transforms_records_the_generator(tmp_path):
    root = generate_scene(make_box_building(), tmp_path, SMALL, seed=9, progress=False)
    meta = json.loads((root / "transforms.json").read_text())
    assert meta["generator"]["seed"] == 9
    assert meta["generator"]["config"]["resolution"] == 40
    assert meta["depth_unit_scale_factor"] == 0.001
    assert meta["semantic_classes"][2] == "window"
