"""Preset runs and the CLI: tiny fixture, resumable runs, a user's mesh, one-line errors."""

import json
import sys
import types
from dataclasses import replace
from pathlib import Path

import pytest
from conftest import TINY_CONFIG, assert_complete_scene, make_box_building
from paths import REPO_ROOT

import dataset.scenes.scene_writer as scene_writer
from dataset.generate import (
    GenerateConfig,
    generate_preset,
    main,
    scene_seed,
)
from dataset.rendering.orbit_views import OrbitConfig
from dataset.rendering.orbit_views import sample_orbit_views as real_sample_orbit_views
from dataset.scenes.scene_writer import scene_changes
from envelope.scenes.scene import read_scene
from envelope.truth import Building

SMALL = GenerateConfig(resolution=40, views=6)


def test_tiny_benchmark_fixture_is_complete(tiny_benchmark):
    names = sorted(p.name for p in tiny_benchmark.iterdir())
    assert names == ["realistic_house", "tiny_l_shaped", "tiny_skyscraper"]
    for root in tiny_benchmark.iterdir():
        assert_complete_scene(root, TINY_CONFIG)
        scene = read_scene(root)
        assert scene.frames_in("ideal") and scene.frames_in("multi")
        facades = {f.id for f in scene.building.facades}
        assert {f.facade_id for f in scene.frames_in("ideal")} <= facades


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


@pytest.mark.slow
def test_preset_run_is_resumable(tmp_path, monkeypatch):
    calls: list = []
    _fake_presets(monkeypatch, calls)
    scenes = generate_preset("boxes", tmp_path, SMALL, progress=False)
    assert [s.name for s in scenes] == ["box_a", "box_b"] and calls == ["box_a", "box_b"]
    for s in scenes:
        assert_complete_scene(s, SMALL)
    # A killed run's leftovers are cleared; finished scenes are skipped.
    (tmp_path / ".box_b.x1.partial").mkdir()
    stamp = (tmp_path / "box_a" / "transforms.json").stat().st_mtime_ns
    generate_preset("boxes", tmp_path, SMALL, progress=False)
    assert calls == ["box_a", "box_b"]
    assert (tmp_path / "box_a" / "transforms.json").stat().st_mtime_ns == stamp
    assert not (tmp_path / ".box_b.x1.partial").exists()
    # Another config never silently mixes into the folder.
    other = replace(SMALL, views=4)
    with pytest.raises(ValueError, match="holds another scene .config changed"):
        generate_preset("boxes", tmp_path, other, progress=False)
    generate_preset("boxes", tmp_path, other, overwrite=True, progress=False)
    assert_complete_scene(tmp_path / "box_a", other)
    with pytest.raises(ValueError, match="unknown preset"):
        generate_preset("nope", tmp_path, SMALL, progress=False)
    with pytest.raises(ValueError, match="workers"):
        generate_preset("boxes", tmp_path, SMALL, workers=0, progress=False)


@pytest.fixture()
def box_ply() -> Path:
    """The importer's closed example mesh (building id ``example_bim``)."""
    return REPO_ROOT / "dataset" / "examples" / "example_bim.ply"


def test_cli_generates_a_users_mesh_and_resumes(tmp_path, box_ply, capsys):
    out = tmp_path / "out"
    args = ["--mesh", str(box_ply), "--out", str(out), "--resolution", "32", "--views", "4",
            "--quiet"]
    assert main(args) == 0
    scene = out / "example_bim"
    assert_complete_scene(scene, GenerateConfig(resolution=32, views=4))
    assert capsys.readouterr().out.strip() == str(scene)
    stamp = (scene / "transforms.json").stat().st_mtime_ns
    assert main(args) == 0
    assert (scene / "transforms.json").stat().st_mtime_ns == stamp


def test_cli_look_photo_changes_the_rgb_and_is_recorded(tmp_path, box_ply):
    common = ["--mesh", str(box_ply), "--resolution", "16", "--views", "1", "--quiet"]
    assert main([*common, "--out", str(tmp_path / "plain")]) == 0
    assert main([*common, "--out", str(tmp_path / "photo"), "--look", "photo"]) == 0
    plain, photo = tmp_path / "plain" / "example_bim", tmp_path / "photo" / "example_bim"
    record = json.loads((photo / "transforms.json").read_text())["generator"]["config"]
    assert record["rgb"]["look"] == "photo"
    assert (plain / "images" / "eval_0000.png").read_bytes() != (
        photo / "images" / "eval_0000.png").read_bytes()
    for truth in ("depth", "semantics"):
        assert (plain / truth / "eval_0000.png").read_bytes() == (
            photo / truth / "eval_0000.png").read_bytes()


def _one_line_error(capsys) -> str:
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err
    return err


def test_cli_bad_inputs_give_one_line_and_exit_code(tmp_path, box_ply, capsys):
    blocker = tmp_path / "a_file"
    blocker.write_text("not a folder")
    assert main(["--mesh", str(box_ply), "--out", str(blocker / "sub"), "--quiet"]) == 2
    assert _one_line_error(capsys).startswith("error: --out ")  # "... is inside the file ..."
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
        m.setattr(scene_writer, "sample_orbit_views", impossible)
        assert main(args) == 2
    assert "cannot frame building 'example_bim'" in _one_line_error(capsys)
    assert not (out / "example_bim").exists()

    def ctrl_c(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(scene_writer, "_render_view", ctrl_c)
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


@pytest.mark.slow
def test_scene_made_by_other_code_is_rerendered_with_the_reason(tmp_path, monkeypatch):
    calls: list = []
    _fake_presets(monkeypatch, calls)
    generate_preset("boxes", tmp_path, SMALL, progress=False)
    tf = tmp_path / "box_a" / "transforms.json"
    meta = json.loads(tf.read_text())
    meta["generator"]["provenance"]["code"]["dataset"] = "0" * 16  # as if older code made it
    tf.write_text(json.dumps(meta))
    logged: list[str] = []
    generate_preset("boxes", tmp_path, SMALL, progress=False, log=logged.append)
    assert calls == ["box_a", "box_b", "box_a"]  # only the stale scene is rendered again
    assert logged == ["box_a: code of dataset changed; re-rendering"]
    assert scene_changes(tmp_path / "box_a", SMALL, scene_seed(0, 1),
                         {"preset": "boxes", "recipe": "box_a"}) == []


def test_preset_run_of_named_buildings_refuses_an_unknown_name(tmp_path):
    with pytest.raises(ValueError, match="preset tiny has no building nope .*tiny_l_shaped"):
        generate_preset("tiny", tmp_path, GenerateConfig(resolution=16, views=1),
                        buildings=["nope"], progress=False)
    assert not any(tmp_path.iterdir())
