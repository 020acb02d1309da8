"""Bad input never becomes a wrong number: every CLI refuses it in one line, with no output.

Families (each case asserts the exit code, the message and that no partial output remains):
a damaged scene folder (``bad_scene_edits.SCENE_EDITS``) through the baselines and neural3d;
command-line values and output paths of every CLI; meshes with NaN, absurd or millimetre
coordinates; malformed JSON of every file the project reads; resources refused before they
are spent (interrupted runs: ``test_interrupts.py``). The conftest box's 64 px scene
(``clean_scene``) is rendered once.
"""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from bad_scene_edits import IDEAL, SCENE_EDITS, TABLE_ROWS, TRAIN, unknown_class_id
from conftest import make_box_building
from paths import REPO_ROOT

from baselines import wwr2ds, wwr2dss
from dataset import generate, importer
from dataset.importers.buildnet3d.meta_data import read_meta_data, write_meta_data
from envelope.mesh import LabelledMesh, write_labelled_ply
from envelope.results import read_result
from envelope.scenes.scene import read_scene
from envelope.warnings_summary import summarise_warnings
from metrics import compare
from neural3d import extract, train
from neural3d.config import config_to_dict, preset_config
from neural3d.field.normalisation import Normalisation

ROOT = REPO_ROOT
BASELINES = {"2D-S": wwr2ds.main, "2D-SS": wwr2dss.main}


@pytest.fixture
def scene(clean_scene, tmp_path) -> Path:
    """A copy of the clean scene at ``tmp_path/bench/box``, free to damage."""
    return Path(shutil.copytree(clean_scene, tmp_path / "bench" / "box", symlinks=True))


def run_main(main, argv: list[str], capsys) -> tuple[int, str]:
    """Exit code and stderr of an in-process CLI; there must be no traceback."""
    code = main([str(a) for a in argv])
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return code, err


def assert_one_error(err: str, pattern: str) -> None:
    """Exactly one ``error:`` line, matching ``pattern``."""
    errors = [line for line in err.splitlines() if line.startswith("error:")]
    assert len(errors) == 1, err
    assert re.search(pattern, errors[0]), errors[0]


# --- a damaged scene: both baselines and neural3d refuse it in one line ----------------------

@pytest.mark.slow
@pytest.mark.parametrize("case", sorted(SCENE_EDITS))
def test_damaged_scene_is_refused_by_2dss(case, scene, capsys):
    edit, pattern = SCENE_EDITS[case]
    edit(scene)
    out = scene.parent.parent / "results"
    code, err = run_main(wwr2dss.main, ["--views", "ideal", "--data", scene, "--out", out], capsys)
    assert code == 2
    assert_one_error(err, pattern)
    assert not out.exists()


@pytest.mark.parametrize("case", TABLE_ROWS)
def test_issue_table_rows_are_refused_by_2ds(case, scene, capsys):
    edit, pattern = SCENE_EDITS[case]
    edit(scene)
    out = scene.parent.parent / "results"
    code, err = run_main(wwr2ds.main, ["--views", "ideal", "--data", scene, "--out", out], capsys)
    assert code == 2
    assert_one_error(err, pattern)
    assert not out.exists()


def test_unknown_class_id_in_a_train_view_stops_training(scene, tmp_path, capsys):
    unknown_class_id(TRAIN)(scene)
    runs = tmp_path / "runs"
    code, err = run_main(train.main, ["--scene", scene, "--preset", "tiny", "--out", runs], capsys)
    assert code == 2
    assert_one_error(err, rf"semantics/{TRAIN} holds class ids .*\(id 77 on \d+ pixels")
    assert not (runs / "box").exists()


def test_degenerate_corners_skip_the_view_with_a_reason(scene, capsys):
    """A facade squashed to one pixel row has no quadrilateral: its facade is missing, said so."""
    from envelope.scenes.images import read_labels, write_labels

    path = scene / "semantics" / IDEAL
    labels = read_labels(path)
    rows = np.flatnonzero((labels > 0).any(axis=1))
    labels[rows[1:]] = 0
    write_labels(path, labels)
    out = scene.parent.parent / "results"
    code, err = run_main(wwr2dss.main, ["--views", "ideal", "--data", scene, "--out", out], capsys)
    assert code == 0
    result = read_result(out / "box__2D-SS__ideal.json")
    fid = json.loads((scene / "transforms.json").read_text())
    fid = next(f["facade_id"] for f in fid["frames"] if f["file_path"] == f"images/{IDEAL}")
    missing = next(f for f in result.facades if f.id == fid)
    assert missing.missing and missing.reason
    assert f"facade {fid}" in err and "skipped" in err


def test_every_view_degenerate_is_an_error_not_a_number(scene, capsys):
    from envelope.scenes.images import write_labels

    for path in (scene / "semantics").glob("ideal_*.png"):
        write_labels(path, np.zeros((64, 64)))
    out = scene.parent.parent / "results"
    code, err = run_main(wwr2dss.main, ["--views", "ideal", "--data", scene, "--out", out], capsys)
    assert code == 2
    assert_one_error(err, "nothing left to measure")
    assert not out.exists()


# --- command-line values and output paths --------------------------------------------------

def _file(tmp_path: Path) -> Path:
    blocker = tmp_path / "a_file"
    blocker.write_text("not a folder")
    return blocker


@pytest.mark.parametrize("method", sorted(BASELINES))
@pytest.mark.parametrize("case, extra, pattern", [
    ("out_is_a_file", lambda t: ["--out", _file(t)], "--out .* is an existing file"),
    ("out_inside_a_file", lambda t: ["--out", _file(t) / "sub"], "is inside the file"),
    ("debug_images_is_a_file", lambda t: ["--debug-images", _file(t)],
     "--debug-images .* is an existing file"),
])
def test_baseline_output_paths(method, case, extra, pattern, scene, tmp_path, capsys):
    argv = ["--views", "ideal", "--data", scene, *extra(tmp_path)]
    code, err = run_main(BASELINES[method], argv, capsys)
    assert code == 2
    assert_one_error(err, pattern)
    assert not (tmp_path / "results").exists()


@pytest.mark.parametrize("argv, pattern", [
    (["--views", "ideal", "--data", "{tmp}/nowhere"], "does not exist"),
    (["--views", "ideal", "--data", "{scene}", "--threads", "0"], "--threads must be >= 1"),
    (["--views", "ideal", "--data", "{scene}", "--device", "tpu"], "device 'tpu'"),
])
def test_2dss_bad_values(argv, pattern, scene, tmp_path, capsys):
    argv = [a.format(tmp=tmp_path, scene=scene) for a in argv]
    code, err = run_main(wwr2dss.main, argv, capsys)
    assert code == 2
    assert_one_error(err, pattern)


@pytest.mark.parametrize("main, argv", [
    (wwr2ds.main, ["--views", "ideal", "--data", ".", "--bogus"]),
    (wwr2dss.main, ["--views", "sideways", "--data", "."]),
    (generate.main, ["--preset", "huge", "--out", "x"]),
    (generate.main, ["--preset", "tiny", "--out", "x", "--resolution", "abc"]),
    (train.main, ["--scene", ".", "--preset", "giant"]),
    (extract.main, ["--run", ".", "--device", "tpu"]),
    (compare.main, ["--neural3d-preset", "huge"]),
    (importer.main, []),
])
def test_unknown_flags_and_values_are_usage_errors(main, argv, capsys):
    with pytest.raises(SystemExit) as info:
        main(argv)
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert "error:" in err and "Traceback" not in err


@pytest.mark.parametrize("argv, pattern", [
    (["--preset", "tiny", "--resolution", "100000"], r"needs about [\d.]+ TiB of memory"),
    (["--preset", "tiny", "--views", "1000000000"], r"needs about [\d.]+ [TP]iB of disk"),
    (["--preset", "tiny", "--resolution", "-5"], "resolution must be >= 8"),
    (["--preset", "tiny", "--workers", "0"], "--workers must be >= 1"),
    (["--preset", "tiny", "--views", "0"], "views must be >= 1"),
    (["--preset", "tiny", "--fov", "0"], "fov_deg must be in"),
    (["--preset", "tiny", "--train-fraction", "2"], "train_fraction must be in"),
    (["--preset", "tiny", "--supersampling", "0"], "supersampling must be >= 1"),
])
def test_generate_refuses_before_spending(argv, pattern, tmp_path, capsys):
    out = tmp_path / "out"
    code, err = run_main(generate.main, [*argv, "--out", out, "--quiet"], capsys)
    assert code == 2
    assert_one_error(err, pattern)
    assert not out.exists()


def test_generate_out_is_a_file(tmp_path, capsys):
    code, err = run_main(generate.main, ["--preset", "tiny", "--out", _file(tmp_path)], capsys)
    assert code == 2
    assert_one_error(err, "--out .* is an existing file")


def test_debug_shows_the_traceback(tmp_path):
    with pytest.raises(ValueError, match="views must be >= 1"):
        generate.main(["--preset", "tiny", "--out", str(tmp_path), "--views", "0", "--debug"])


def test_a_bug_is_one_line_that_points_at_debug(tmp_path, capsys, monkeypatch):
    def broken(*args, **kwargs):
        raise ZeroDivisionError("division by zero")

    monkeypatch.setattr(generate, "generate_entries", broken)
    code, err = run_main(generate.main, ["--preset", "tiny", "--out", tmp_path / "o"], capsys)
    assert code == 1
    assert err.strip().count("\n") == 0
    assert "internal error in dataset.generate: ZeroDivisionError" in err and "--debug" in err


# --- meshes ----------------------------------------------------------------------------------

def _box_mesh_file(tmp_path: Path, scale: float = 1.0, nan: bool = False) -> Path:
    mesh = make_box_building().mesh
    v = mesh.vertices_m * scale
    if nan:
        v[3] = np.nan
    path = tmp_path / "house.ply"
    write_labelled_ply(path, LabelledMesh(v, mesh.faces, mesh.face_label, mesh.face_facade))
    return path


def _text(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


@pytest.mark.parametrize("make, pattern", [
    (lambda t: _box_mesh_file(t, nan=True), "1 of .* vertices have NaN or infinite coordinates"),
    (lambda t: _box_mesh_file(t, scale=1000.0), "likely in millimetres"),
    (lambda t: _box_mesh_file(t, scale=1e6), "larger than 2 km; check the file's units"),
    (lambda t: _box_mesh_file(t, scale=1e-3), "smaller than 1 m"),
    (lambda t: _text(t / "e.ply", ""), "e.ply"),
    (lambda t: _text(t / "g.obj", "v 0 0 x\n"), "line 1: cannot parse"),
    (lambda t: _text(t / "f.obj", "v 0 0 0\ng wall\nf 1 2 3\n"),
     "refers to a vertex that does not exist"),
    (lambda t: _text(t / "h.stl", "solid"), "unsupported mesh format"),
])
def test_bad_meshes_get_their_own_message(make, pattern, tmp_path, capsys):
    out = tmp_path / "out"
    code, err = run_main(generate.main, ["--mesh", make(tmp_path), "--out", out, "--quiet"],
                         capsys)
    assert code == 2
    assert_one_error(err, pattern)
    assert not out.exists() or not any(out.iterdir())


# --- malformed JSON of every file the project reads ----------------------------------------

@pytest.mark.parametrize("case, pattern", [
    ("traversal", "leaves the scene folder"),
    ("nan_pose", "NaN or inf"),
    ("truncated", "is not a valid meta_data.json"),
    ("frames_not_objects", "is not a valid meta_data.json"),
])
def test_meta_data_is_validated_like_transforms(case, pattern, scene):
    write_meta_data(read_scene(scene), scene)
    path = scene / "meta_data.json"
    meta = json.loads(path.read_text())
    if case == "traversal":
        meta["frames"][0]["rgb_path"] = "../../../etc/passwd"
    elif case == "nan_pose":
        meta["frames"][0]["camtoworld"][0][0] = float("nan")
    elif case == "frames_not_objects":
        meta["frames"] = [1, 2]
    text = json.dumps(meta)
    path.write_text(text[: len(text) // 2] if case == "truncated" else text)
    with pytest.raises(ValueError, match=pattern):
        read_meta_data(path, class_ids="envelope_bench")


def _fake_run(folder: Path, config="valid", run="valid", checkpoint=b"garbage") -> Path:
    folder.mkdir(parents=True)
    cfg = json.dumps(config_to_dict(preset_config("tiny"))) if config == "valid" else config
    norm = Normalisation.from_box(np.array([-10.0, -6, 0]), np.array([10.0, 6, 9]))
    info = json.dumps({"scene_dir": str(folder), "class_names": ["background", "wall"],
                       "normalisation": norm.to_json_dict()}) if run == "valid" else run
    (folder / "config.json").write_text(cfg)
    (folder / "run.json").write_text(info)
    (folder / "checkpoint.pt").write_bytes(checkpoint)
    return folder


@pytest.mark.parametrize("make, argv, pattern", [
    (lambda t: t / "nowhere", [], "does not exist"),
    (lambda t: _fake_run(t / "r", config="{"), [], "damaged config.json or run.json"),
    (lambda t: _fake_run(t / "r", run='{"class_names": 3}'), [], "damaged config.json or run.json"),
    (lambda t: _fake_run(t / "r"), [], "checkpoint .* cannot be read"),
    (lambda t: _fake_run(t / "r", checkpoint=b""), [], "checkpoint .* cannot be read"),
    (lambda t: _fake_run(t / "r"), ["--resolution", "100000"], r"needs about [\d.]+ TiB of memory"),
    (lambda t: _fake_run(t / "r"), ["--resolution", "4"], "resolution must be >= 8"),
    (lambda t: _fake_run(t / "r"), ["--out", "{file}"], "--out .* is an existing file"),
])
def test_extract_refuses_a_damaged_run(make, argv, pattern, tmp_path, capsys):
    run = make(tmp_path)
    argv = [a.format(file=_file(tmp_path)) for a in argv]
    code, err = run_main(extract.main, ["--run", run, *argv], capsys)
    assert code == 2
    assert_one_error(err, pattern)
    assert not (run / "extract").exists()


@pytest.mark.parametrize("argv, pattern", [
    (["--scene", "{tmp}/nowhere"], "no transforms.json"),
    (["--scene", "{scene}", "--out", "{file}"], "--out .* is an existing file"),
    (["--scene", "{scene}", "--max-minutes", "-1"], "--max-minutes must be > 0"),
    (["--scene", "{scene}", "--iterations", "0"], "iterations must be positive"),
    (["--scene", "{scene}", "--resume", "--preset", "tiny"], "cannot resume"),
    (["--scene", "{scene}", "--device", "tpu"], "device 'tpu'"),
])
def test_train_refuses_bad_values(argv, pattern, scene, tmp_path, capsys):
    runs = tmp_path / "runs"
    argv = [a.format(tmp=tmp_path, scene=scene, file=_file(tmp_path)) for a in argv]
    code, err = run_main(train.main, [*argv, "--out", runs] if "--out" not in argv else argv,
                         capsys)
    assert code == 2
    assert_one_error(err, pattern)
    assert not (runs / "box" / "checkpoint.pt").exists()


def test_train_resume_with_a_damaged_config(scene, tmp_path, capsys):
    (tmp_path / "runs" / "box").mkdir(parents=True)
    (tmp_path / "runs" / "box" / "config.json").write_text('{"iterations": ')
    code, err = run_main(train.main, ["--scene", scene, "--resume", "--out", tmp_path / "runs"],
                         capsys)
    assert code == 2
    assert_one_error(err, "config.json is not a valid neural3d config")


@pytest.mark.parametrize("argv, pattern", [
    (["--data", "{tmp}/nowhere"], "does not exist"),
    (["--methods", "2D-X"], "unknown method '2D-X'"),
    (["--views", "sideways"], "unknown views 'sideways'"),
    (["--out", "{file}"], "--out .* is an existing file"),
    (["--results", "{file}"], "--results .* is an existing file"),
    (["--neural3d-max-minutes", "-1"], "max minutes must be > 0"),
    (["--neural3d-steps", "0"], "steps must be >= 1"),
])
def test_compare_refuses_bad_values(argv, pattern, scene, tmp_path, capsys):
    argv = [a.format(tmp=tmp_path, file=_file(tmp_path)) for a in argv]
    if "--data" not in argv:
        argv = ["--data", scene.parent, *argv]
    code, err = run_main(compare.main, argv, capsys)
    assert code == 2
    assert_one_error(err, pattern)
    assert not (tmp_path / "bench-compare").exists()


@pytest.mark.slow
@pytest.mark.parametrize("damage, expect", [
    ("result", "corrupt result file"),
    ("building", "building.json"),
    ("transforms", "transforms.json is malformed"),
])
def test_compare_names_a_damaged_file_and_trusts_nothing_half_written(damage, expect, scene,
                                                                      capsys):
    bench, results = scene.parent, scene.parent.parent / "results"
    argv = ["--data", bench, "--methods", "2D-S", "--views", "ideal", "--results", results,
            "--out", scene.parent.parent / "cmp"]
    result_file = results / "box__2D-S__ideal.json"
    if damage == "result":
        results.mkdir()
        result_file.write_text('{"scene": "box", "wwr": 0.9')  # half-written
    elif damage == "building":
        (scene / "building.json").write_text("{")
    else:
        (scene / "transforms.json").write_text("{")
    code = compare.main([str(a) for a in argv])
    out = capsys.readouterr()
    assert code == 0 and "Traceback" not in out.err
    assert expect in out.out + out.err
    if damage == "transforms":
        assert not result_file.exists()  # a failed run leaves no result
    elif damage == "building":  # methods never read the truth: only metrics sees the damage
        assert read_result(result_file).wwr is not None
    else:
        assert read_result(result_file).wwr is not None  # recomputed, not trusted


def test_warnings_are_summarised_one_line_per_kind():
    lines = summarise_warnings([
        "box: view images/multi_0003.png (facade 3) skipped: the facade is cut off",
        "box: view images/multi_0007.png (facade 2) skipped: the facade is cut off",
        "box: 1 of 4 facades missing",
    ])
    assert lines == ["box: view images/multi_0003.png (facade 3) skipped: the facade is cut off "
                     "(2 warnings like this)", "box: 1 of 4 facades missing"]
