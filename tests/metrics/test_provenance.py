"""Provenance records key every cache: code, inputs, config and libraries; stale rows are marked."""

import importlib
import sys
from dataclasses import replace
from pathlib import Path

import pytest
from metrics_helpers import make_result, make_truth

from envelope.provenance import (
    Provenance,
    code_fingerprint,
    make_provenance,
    provenance_changes,
)
from envelope.results import read_result, write_result
from envelope.scenes.scene import find_scene_folders
from envelope.truth import write_building
from metrics.compare import main
from metrics.report.report import table2_errors
from metrics.report.tables import read_csv_rows
from metrics.run.runner import MethodSpec, folder_spec, run_missing
from metrics.score.aggregate import aggregate_by_family
from metrics.score.errors import building_errors

TOY_SOURCE = '''"""A throwaway method for the cache tests."""
from dataclasses import replace


def run(result, scene_dir, protocol):
    return replace(result, wwr={wwr})
'''


def test_record_round_trip_and_changes_in_words():
    a = make_provenance({"k": 1, "nested": {"x": (1, 2)}}, modules=("envelope.wwr",),
                        inputs={"scene": "abc"})
    assert Provenance.from_json_dict(a.to_json_dict()) == a
    assert provenance_changes(a, a) == []
    b = replace(a, config={"k": 2, "nested": {"x": [1, 3]}}, inputs={"scene": "def"},
                code={"envelope.wwr": "0" * 16}, environment={**a.environment, "numpy": "0.1"})
    said = [str(c) for c in provenance_changes(a, b)]
    assert said == ["code of envelope.wwr changed", "inputs changed (scene re-rendered)",
                    "config changed: k 1 -> 2, nested.x [1, 2] -> [1, 3]",
                    f"numpy {a.environment['numpy']} -> 0.1"]
    assert [c.part for c in provenance_changes(None, a)] == ["record"]
    with pytest.raises(ValueError, match="not a provenance record"):
        Provenance.from_json_dict({"config": {}})


def _scenes(root: Path, names=("a", "b")) -> list[Path]:
    for name in names:
        write_building(root / name / "building.json", make_truth(name))
        (root / name / "transforms.json").write_text(f'{{"render": "{name} v1"}}')
    return find_scene_folders(root)


def _toy_spec(tmp_path: Path, name: str, wwr: float) -> MethodSpec:
    """A method whose code is the module ``name`` written into ``tmp_path``."""
    (tmp_path / f"{name}.py").write_text(TOY_SOURCE.format(wwr=wwr))
    module = importlib.import_module(name)

    def run(scene_dir: Path, protocol: str):
        return importlib.reload(module).run(make_result("x", name, protocol, 0.0), scene_dir,
                                            protocol)

    return folder_spec(name, ("ideal",), {"weighting": "area"}, run, packages=(name,))


def test_changing_a_methods_source_recomputes_its_results_only(tmp_path, monkeypatch):
    monkeypatch.syspath_prepend(str(tmp_path))
    scenes = _scenes(tmp_path / "data")
    results = tmp_path / "results"
    specs = [_toy_spec(tmp_path, "toy_method_a", 0.25), _toy_spec(tmp_path, "toy_method_b", 0.5)]
    first = run_missing(scenes, specs, results, log=lambda _: None)
    assert [o.status for o in first] == ["ran"] * 4
    assert read_result(results / "a__toy_method_a__ideal.json").provenance.code == {
        "envelope": code_fingerprint("envelope"),
        "toy_method_a": code_fingerprint("toy_method_a")}
    again = run_missing(scenes, specs, results, log=lambda _: None)
    assert [o.status for o in again] == ["reused"] * 4  # an unchanged rerun computes nothing
    # A new version of method a (a new process would fingerprint the new source).
    specs[0] = _toy_spec(tmp_path, "toy_method_a", 0.3)
    code_fingerprint.cache_clear()
    said: list[str] = []
    redo = run_missing(scenes, specs, results, log=said.append)
    assert [(o.scene, o.method, o.status) for o in redo] == [
        ("a", "toy_method_a", "ran"), ("a", "toy_method_b", "reused"),
        ("b", "toy_method_a", "ran"), ("b", "toy_method_b", "reused")]
    assert said == [f"{s} / toy_method_a / ideal: code of toy_method_a changed; recomputing"
                    for s in ("a", "b")]
    assert read_result(results / "a__toy_method_a__ideal.json").wwr == 0.3
    sys.modules.pop("toy_method_a"), sys.modules.pop("toy_method_b")


def test_a_rerendered_scene_recomputes_its_results_and_stale_ones_can_be_kept(tmp_path,
                                                                                 monkeypatch):
    monkeypatch.syspath_prepend(str(tmp_path))
    scenes = _scenes(tmp_path / "data")
    results = tmp_path / "results"
    specs = [_toy_spec(tmp_path, "toy_method_c", 0.25)]
    run_missing(scenes, specs, results, log=lambda _: None)
    (scenes[0] / "transforms.json").write_text('{"render": "a v2"}')
    said: list[str] = []
    kept = run_missing(scenes, specs, results, reuse_stale=True, log=said.append)
    assert [o.status for o in kept] == ["stale", "reused"]
    assert said == ["a / toy_method_c / ideal: kept although stale "
                    "(inputs changed (scene re-rendered))"]
    row = building_errors(kept[0].result, make_truth("a"), stale=True)
    assert row.marks == "stale"
    table = table2_errors(aggregate_by_family([row]))
    assert table.rows[0][-1] == "stale: 1" and any("--reuse-stale" in n for n in table.notes)
    redo = run_missing(scenes, specs, results, log=lambda _: None)
    assert [o.status for o in redo] == ["ran", "reused"]
    sys.modules.pop("toy_method_c")


@pytest.mark.slow
def test_a_result_cut_short_is_marked_in_every_table(tmp_path, capsys):
    data, results, out = tmp_path / "data", tmp_path / "results", tmp_path / "out"
    write_building(data / "sky_a" / "building.json", make_truth("sky_a"))
    result = replace(make_result("sky_a", "neural3d", "train", 0.3), steps=400, cut_short=True)
    write_result(results, result)
    assert main(["--data", str(data), "--results", str(results), "--out", str(out),
                 "--methods", "neural3d", "--no-run"]) == 0
    for name in ("table2_errors", "table3_footprint_iou"):
        rows = read_csv_rows((out / f"{name}.csv").read_text())
        assert rows[0]["steps"] == "400" and "cut short: 1" in rows[0]["marks"]
        assert "the wall-clock safety cap stopped training" in (out / f"{name}.md").read_text()
    per_building = read_csv_rows((out / "per_building.csv").read_text())
    assert per_building[0]["marks"] == "cut short; stale"  # hand-made: no provenance record
    assert "cut short" in capsys.readouterr().out


@pytest.mark.slow
def test_two_clean_comparisons_write_identical_tables(tiny_benchmark, tmp_path, monkeypatch):
    """Same command, same machine, clean caches: byte-identical tables (timing kept apart)."""
    argv = ["--data", str(tiny_benchmark), "--methods", "2D-S,2D-SS,neural3d",
            "--views", "ideal,train", "--neural3d-preset", "tiny", "--neural3d-steps", "20",
            "--neural3d-resolution", "24", "--results", "results", "--out", "out"]
    texts = []
    for run in ("first", "second"):
        (tmp_path / run).mkdir()
        monkeypatch.chdir(tmp_path / run)
        assert main(argv) == 0
        texts.append({name: (tmp_path / run / "out" / name).read_text()
                      for name in ("table2_errors.csv", "table3_footprint_iou.csv",
                                   "per_building.csv", "per_facade.csv", "table2_errors.md")})
    assert texts[0] == texts[1]
    rows = read_csv_rows(texts[0]["table2_errors.csv"])
    assert {r["method"] for r in rows} == {"2D-S", "2D-SS", "neural3d"}
    assert {r["steps"] for r in rows if r["method"] == "neural3d"} == {"20"}
    assert "neural3d: tiny preset, 20 steps" in texts[0]["table2_errors.md"]
