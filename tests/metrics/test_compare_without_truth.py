"""A comparison on scenes without truth (no building.json: a user's photos) gives estimates,
never errors, and says so; a folder mixing both is scored over the scenes with truth.

The scenes are the rendered box building (``clean_scene``) with and without its
``building.json``; the 2D methods run on its ideal views (on a copy with orbit frames only,
what a photos scene is, on its ``train`` views). The estimates on the copy without
truth must equal those of the same methods on the copy with it: the truth is never read by a
method, only by the scoring.
"""

from __future__ import annotations

import contextlib
import io
import json
import shutil
from pathlib import Path

import pytest

from metrics.compare import main
from metrics.comparison import EXPORT_FOLDER, compare
from metrics.report.html_report import REPORT_FILE
from metrics.report.report import PER_BUILDING_NAME, TABLE2_NAME, TABLE3_NAME
from metrics.report.report_data import read_report_data
from metrics.report.report_estimates import ESTIMATES_NAME, estimates_table
from metrics.report.tables import read_csv_rows
from metrics.run.methods import method_specs
from metrics.run.predicted_masks import TABLE_NAME
from neural3d.method import Neural3dBudget

NO_TRUTH_TEXT = "no ground truth (building.json) in any scene"


def _scene(clean_scene: Path, folder: Path, name: str, *, truth: bool) -> Path:
    shutil.copytree(clean_scene, folder / name)
    if not truth:
        (folder / name / "building.json").unlink()
    return folder / name


def _compare(data: Path, tmp: Path, methods=("2D-S", "2D-SS"), views=("ideal",), configs=None):
    specs = method_specs(methods, views, tmp / f"{data.name}-results", configs=configs)
    out = tmp / f"{data.name}-compare"
    return compare(data, specs, tmp / f"{data.name}-results", out), out


@pytest.fixture(scope="module")
def both(clean_scene, tmp_path_factory):
    """The 2D methods compared on the box with its truth and on the box without."""
    tmp = tmp_path_factory.mktemp("without_truth")
    _scene(clean_scene, tmp / "truth", "box", truth=True)
    _scene(clean_scene, tmp / "none", "box", truth=False)
    return _compare(tmp / "truth", tmp), _compare(tmp / "none", tmp)


@pytest.mark.slow  # the module's fixture runs two comparisons (about 6 s)
def test_estimates_without_truth_are_those_of_the_scene_with_truth(both):
    (scored, _), (unscored, _) = both
    assert [o.status for o in unscored.outcomes] == ["ran"] * 2
    same = estimates_table(scored.outcomes, ["box"])
    assert unscored.estimates is not None and unscored.estimates.rows == same.rows
    by_key = dict(zip(unscored.estimates.keys, unscored.estimates.rows[0]))
    assert by_key["status"] == "ok" and 0 < by_key["wwr"] < 1 and by_key["facades"] == 4


@pytest.mark.slow  # the module's fixture runs two comparisons (about 6 s)
def test_without_truth_there_is_no_error_table_only_estimates(both):
    (scored, _), (unscored, out) = both
    assert scored.table2 is not None and scored.estimates is None
    assert unscored.rows == () and unscored.facade_rows == ()
    assert unscored.table2 is None and unscored.table3 is None and unscored.orientation is None
    assert [t.name for t in unscored.tables] == [ESTIMATES_NAME]
    assert [t.name for t in unscored.printed] == [ESTIMATES_NAME]
    for stem in (TABLE2_NAME, TABLE3_NAME, PER_BUILDING_NAME, "per_facade",
                 "table_orientation_wwr"):
        assert not list(out.glob(f"{stem}.*")), stem
    text = (out / f"{ESTIMATES_NAME}.csv").read_text()
    assert NO_TRUTH_TEXT in text and "_ape" not in text and "iou" not in text
    assert json.loads((out / "provenance.json").read_text())["scenes_without_truth"] == ["box"]


@pytest.mark.slow  # the module's fixture runs two comparisons (about 6 s)
def test_the_exports_and_the_report_say_there_is_no_truth(both):
    (_, _), (unscored, out) = both
    facades = (out / EXPORT_FOLDER / "facades.csv").read_text()
    assert NO_TRUTH_TEXT in facades.splitlines()[0]
    rows = read_csv_rows(facades)
    assert {(r["method"], r["facade"]) for r in rows} == {
        (m, str(f)) for m in ("2D-S", "2D-SS") for f in range(1, 5)}
    assert all(r["method"] != "truth" and r["orientation"] == "" for r in rows)
    wwr_2ds = {float(r["wwr"]) for r in rows if r["method"] == "2D-S"}
    assert len(wwr_2ds) >= 1 and all(0 <= w <= 1 for w in wwr_2ds)
    for name in ("orientations.csv", "energyplus_wwr.csv", "cea_architecture.csv"):
        assert NO_TRUTH_TEXT in (out / EXPORT_FOLDER / name).read_text(), name
    page = (out / REPORT_FILE).read_text()
    assert NO_TRUTH_TEXT in page and "none (no building.json)" in page
    assert "Table 2: errors per family" not in page and "WWR error (%)" not in page


@pytest.mark.slow  # the module's fixture runs two comparisons (about 6 s)
def test_the_report_is_rebuilt_from_a_folder_without_truth(both):
    (_, _), (unscored, out) = both
    data = read_report_data(out)
    assert [(r.scene, r.family, r.method, r.status) for r in data.rows] == [
        ("box", "unknown", "2D-S", "ok"), ("box", "unknown", "2D-SS", "ok")]
    assert [r.wwr_est for r in data.rows] == pytest.approx(
        [row[6] for row in unscored.estimates.rows], rel=1e-9)
    assert all(r.wwr_ape is None and r.wwr_true is None for r in data.rows)


@pytest.mark.slow  # the module's fixture runs two comparisons (about 6 s)
def test_a_mixed_folder_is_scored_over_the_scenes_with_truth(clean_scene, tmp_path, both):
    (scored, _), _ = both
    _scene(clean_scene, tmp_path / "mixed", "box", truth=True)
    _scene(clean_scene, tmp_path / "mixed", "photos", truth=False)
    mixed, out = _compare(tmp_path / "mixed", tmp_path)
    assert {r.scene for r in mixed.rows} == {"box"}
    assert mixed.table2 is not None and mixed.table2.rows == scored.table2.rows
    assert any("errors are over the 1 of 2 scenes" in n for n in mixed.table2.notes)
    assert {r[0] for r in mixed.estimates.rows} == {"box", "photos"}
    assert {r["scene"] for r in read_csv_rows((out / f"{PER_BUILDING_NAME}.csv").read_text())
            } == {"box"}
    facades = read_csv_rows((out / EXPORT_FOLDER / "facades.csv").read_text())
    assert {(r["building"], r["method"]) for r in facades} >= {
        ("box", "truth"), ("box", "2D-S"), ("photos", "2D-S")}
    assert all(r["orientation"] != "" for r in facades if r["building"] == "box")
    page = (out / REPORT_FILE).read_text()
    assert "Table 2: errors per family" in page and "photos have none: estimates only" in page


@pytest.mark.slow  # a whole comparison with its outputs (about 2 s)
def test_the_2d_methods_measure_a_scene_of_orbit_frames_only(clean_scene, tmp_path):
    """What a photos scene is (docs/importing.md section 9): `train` frames only, no facade
    ids, no truth. With `--views train` both 2D methods run on it (they declare `train`),
    find their own facades and give their normals to the exports."""
    scene = _scene(clean_scene, tmp_path / "orbit", "box", truth=False)
    meta = json.loads((scene / "transforms.json").read_text())
    meta["frames"] = [f for f in meta["frames"] if f["split"] == "train"]
    assert meta["frames"] and all(f.get("facade_id") is None for f in meta["frames"])
    (scene / "transforms.json").write_text(json.dumps(meta))
    comparison, out = _compare(tmp_path / "orbit", tmp_path, views=("train",))
    rows = [dict(zip(comparison.estimates.keys, r)) for r in comparison.estimates.rows]
    assert [(r["method"], r["protocol"], r["status"]) for r in rows] == [
        ("2D-S", "train", "ok"), ("2D-SS", "train", "ok")], [r["reason"] for r in rows]
    assert all(r["facades"] >= 1 for r in rows)
    facades = read_csv_rows((out / EXPORT_FOLDER / "facades.csv").read_text())
    assert {r["method"] for r in facades} == {"2D-S", "2D-SS"}
    assert all(r["azimuth_from"] == "estimate normal" for r in facades if r["wwr"] != "")


def test_a_method_needing_depth_is_refused_per_building_with_its_reason(clean_scene, tmp_path):
    scene = _scene(clean_scene, tmp_path / "nodepth", "box", truth=False)
    meta = json.loads((scene / "transforms.json").read_text())
    for frame in meta["frames"]:
        del frame["depth_file_path"]
    (scene / "transforms.json").write_text(json.dumps(meta))
    shutil.rmtree(scene / "depth")
    comparison, _ = _compare(tmp_path / "nodepth", tmp_path)
    rows = {r[1]: dict(zip(comparison.estimates.keys, r)) for r in comparison.estimates.rows}
    assert rows["2D-SS"]["status"] == "failed" and "no depth_file_path" in rows["2D-SS"]["reason"]
    assert rows["2D-S"]["status"] == "ok"  # 2D-S reads depth where there is some


@pytest.mark.slow
def test_neural3d_estimates_a_footprint_without_truth(clean_scene, tmp_path):
    """Trained twice from scratch (tiny preset, 60 steps): with and without truth."""
    budget = {"neural3d": Neural3dBudget(preset="tiny", steps=60, threads=1, resolution=24,
                                         eval_frames=1)}
    _scene(clean_scene, tmp_path / "truth", "box", truth=True)
    _scene(clean_scene, tmp_path / "none", "box", truth=False)
    runs = [_compare(tmp_path / d, tmp_path, ("neural3d",), ("train",), budget)
            for d in ("truth", "none")]
    (scored, _), (unscored, out) = runs
    assert unscored.estimates.rows == estimates_table(scored.outcomes, ["box"]).rows
    row = dict(zip(unscored.estimates.keys, unscored.estimates.rows[0]))
    assert row["status"] == "ok" and row["footprint_m2"] > 0
    assert scored.table3 is not None and unscored.table3 is None
    facades = read_csv_rows((out / EXPORT_FOLDER / "facades.csv").read_text())
    assert facades and all(r["azimuth_from"] == "estimate normal" for r in facades
                           if r["wwr"] != "")


@pytest.mark.slow
def test_predicted_masks_without_truth_print_the_estimates_not_a_table_of_errors(
        clean_scene, tmp_path):
    _scene(clean_scene, tmp_path / "data", "box", truth=False)
    stdout = io.StringIO()
    with contextlib.redirect_stdout(stdout):
        code = main(["--data", str(tmp_path / "data"), "--methods", "2D-S", "--views", "ideal",
                     "--results", str(tmp_path / "r"), "--out", str(tmp_path / "o"),
                     "--masks", "predicted", "--masks-threads", "1"])
    assert code == 0
    printed = stdout.getvalue()
    assert NO_TRUTH_TEXT in printed and "Exact masks vs predicted masks" not in printed
    (predicted_out,) = tmp_path.glob("o-masks-*")
    assert not list(predicted_out.glob(f"{TABLE_NAME}.*"))
    rows = read_csv_rows((predicted_out / f"{ESTIMATES_NAME}.csv").read_text())
    assert [(r["scene"], r["method"], r["status"]) for r in rows] == [("box", "2D-S", "ok")]
