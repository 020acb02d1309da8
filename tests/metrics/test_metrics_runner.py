"""Running only what is missing: reuse by provenance, recompute on change or corruption."""

from dataclasses import replace
from pathlib import Path

from metrics_helpers import make_result, make_truth

from envelope.results import read_result
from envelope.scenes.scene import find_scene_folders
from envelope.truth import write_building
from metrics.run.runner import folder_spec, run_missing


class FakeMethod:
    """A method that counts its calls and fails on scenes named in ``fail_on``."""

    def __init__(self, config, fail_on=()):
        self.config, self.fail_on, self.calls = config, set(fail_on), []

    def __call__(self, scene_dir: Path, protocol: str):
        self.calls.append((scene_dir.name, protocol))
        if scene_dir.name in self.fail_on:
            raise RuntimeError("no facade pixels in any view")
        result = make_result("ignored-name", "fake", protocol, 0.25)
        return replace(result, config=dict(self.config))


def _scenes(root: Path, names=("a", "b")) -> list[Path]:
    for name in names:
        write_building(root / name / "building.json", make_truth(name))
    return find_scene_folders(root)


def test_runs_missing_then_reuses_then_recomputes_on_config_change(tmp_path):
    scenes = _scenes(tmp_path / "data")
    method = FakeMethod({"k": 1})
    spec = folder_spec("fake", ("ideal", "multi"), {"k": 1}, method)
    out = run_missing(scenes, [spec], tmp_path / "results", log=lambda _: None)
    assert [(o.scene, o.protocol, o.status) for o in out] == [
        ("a", "ideal", "ran"), ("a", "multi", "ran"), ("b", "ideal", "ran"), ("b", "multi", "ran")
    ]
    stored = read_result(tmp_path / "results" / "a__fake__ideal.json")
    assert stored.scene == "a"  # the file is named and filled after the scene folder
    again = run_missing(scenes, [spec], tmp_path / "results", log=lambda _: None)
    assert {o.status for o in again} == {"reused"} and len(method.calls) == 4
    changed = folder_spec("fake", ("ideal",), {"k": 2}, FakeMethod({"k": 2}))
    messages = []
    redo = run_missing(scenes, [changed], tmp_path / "results", log=messages.append)
    assert [o.status for o in redo] == ["ran", "ran"]
    assert "config changed: k 1 -> 2; recomputing" in messages[0]


def test_failure_is_recorded_and_the_rest_runs(tmp_path):
    scenes = _scenes(tmp_path / "data", ("a", "b", "c"))
    spec = folder_spec("fake", ("ideal",), {}, FakeMethod({}, fail_on={"b"}))
    out = run_missing(scenes, [spec], tmp_path / "results", log=lambda _: None)
    assert [o.status for o in out] == ["ran", "failed", "ran"]
    assert out[1].reason.startswith("RuntimeError: no facade pixels in any view (at tests/")
    assert not (tmp_path / "results" / "b__fake__ideal.json").exists()


def test_corrupt_file_is_reported_and_recomputed_or_failed(tmp_path):
    scenes = _scenes(tmp_path / "data", ("a",))
    results = tmp_path / "results"
    results.mkdir()
    (results / "a__fake__ideal.json").write_text("{not json")
    messages = []
    spec = folder_spec("fake", ("ideal",), {}, FakeMethod({}))
    read_only = run_missing(scenes, [spec], results, allow_run=False, log=messages.append)
    assert read_only[0].status == "failed"
    assert "corrupt result file" in read_only[0].reason and "is not a valid result" in messages[0]
    redo = run_missing(scenes, [spec], results, log=messages.append)
    assert redo[0].status == "ran" and "recomputing" in messages[-1]
    assert read_result(results / "a__fake__ideal.json").wwr == 0.25


def test_no_run_reports_missing_results(tmp_path):
    scenes = _scenes(tmp_path / "data", ("a",))
    spec = folder_spec("fake", ("ideal",), {"k": 1}, FakeMethod({}))
    out = run_missing(scenes, [spec], tmp_path / "results", allow_run=False, log=lambda _: None)
    assert out[0].status == "failed" and "no result file a__fake__ideal.json" in out[0].reason



def test_the_result_file_is_named_by_the_spec_whatever_the_method_calls_itself(tmp_path):
    """A method whose results carry another name is still found again: the file is named
    by its Method's name, so the cache cannot silently miss."""
    scenes = _scenes(tmp_path / "data", ("a",))
    spec = folder_spec("fake", ("ideal",), {}, lambda d, p: make_result("a", "other", p, 0.5))
    (ran,) = run_missing(scenes, [spec], tmp_path / "results", log=lambda _: None)
    assert ran.path == tmp_path / "results" / "a__fake__ideal.json"
    assert read_result(ran.path).method == "fake"
    (again,) = run_missing(scenes, [spec], tmp_path / "results", log=lambda _: None)
    assert again.status == "reused"
