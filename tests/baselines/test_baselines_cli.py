"""baselines.cli and both CLIs: on the tiny benchmark (fixture from conftest), on the built-in
default benchmark without --data, writing where metrics.compare reads, printing what they
measured."""

import shutil
from functools import partial

import pytest

import baselines.cli
from baselines import wwr2ds, wwr2dss
from dataset.benchmark_cache import (
    DefaultBenchmark,
    benchmark_of_results,
    default_results_folder,
)
from envelope.method import available_methods
from envelope.results import MethodResult, read_result
from envelope.scenes.scene import find_scene_folders
from envelope.truth import read_building
from metrics.run.compare_args import compare_request, parse_compare_args


def test_one_default_results_folder_for_every_command(tmp_path):
    """The 2D command lines, compare and export all name a benchmark's results folder by
    dataset.benchmark_cache.default_results_folder (export also reads it backwards)."""
    from metrics.export.command import _parse_args, _paths

    bench = tmp_path / "bench"
    bench.mkdir()
    assert default_results_folder(bench) == tmp_path / "bench-results"
    assert default_results_folder(bench / "a") == bench / "a-results"
    assert benchmark_of_results(default_results_folder(bench)) == bench
    assert benchmark_of_results(tmp_path / "results") is None
    methods = available_methods()
    request = compare_request(parse_compare_args(["--data", str(bench)], methods), methods)
    assert request.results == default_results_folder(bench)
    results, data, out = _paths(_parse_args(["--results", str(request.results)]))
    assert (results, data, out) == (request.results, bench, tmp_path / "bench-export")
    default = DefaultBenchmark().folder
    assert _paths(_parse_args([]))[:2] == (default_results_folder(default), default)


@pytest.mark.slow
@pytest.mark.parametrize("views", ["ideal", "multi"])
def test_both_clis_on_the_tiny_benchmark(tiny_benchmark, tmp_path, views):
    out = tmp_path / "results"
    assert wwr2ds.main(["--views", views, "--data", str(tiny_benchmark), "--out", str(out)]) == 0
    assert wwr2dss.main(["--views", views, "--data", str(tiny_benchmark), "--out", str(out),
                         "--debug-images", str(tmp_path / "dbg")]) == 0
    scenes = find_scene_folders(tiny_benchmark)
    for scene in scenes:
        truth = read_building(scene / "building.json")
        for method in ("2D-S", "2D-SS"):
            r = read_result(out / f"{scene.name}__{method}__{views}.json")
            assert (r.scene, r.method, r.protocol) == (scene.name, method, views)
            assert {f.id for f in r.facades} <= {f.id for f in truth.facades}
            assert 0 <= r.wwr <= 1 and r.code_version and r.wall_time_s > 0
            # 96 px images: a loose sanity bound, not an accuracy test.
            assert abs(r.wwr - truth.wwr) < 0.1
    assert any((tmp_path / "dbg").glob(f"*__{views}__f1__v0__rectified.png"))


def assert_table_shows(out: str, result: MethodResult) -> None:
    """The printed table holds the building's WWR and each facade's row as in the file."""
    head = f"{result.scene}  {result.method} {result.protocol}: building WWR {result.wwr:.3f}"
    assert head in out
    rows = {tuple(line.split()[:2]) for line in out.splitlines() if line.startswith("  ")}
    for f in result.facades:
        assert (str(f.id), "-" if f.wwr is None else f"{f.wwr:.3f}") in rows


def test_results_go_where_compare_reads_them_and_are_printed(clean_scene, tmp_path, capsys):
    data = tmp_path / "bench"
    shutil.copytree(clean_scene, data / clean_scene.name)
    assert wwr2ds.main(["--views", "ideal", "--data", str(data)]) == 0
    methods = available_methods()
    request = compare_request(parse_compare_args(["--data", str(data), "--no-run"], methods),
                              methods)
    path = request.results / f"{clean_scene.name}__2D-S__ideal.json"
    out = capsys.readouterr().out
    assert_table_shows(out, read_result(path))
    assert f"-> {path}" in out


@pytest.mark.parametrize("cli, name", [(wwr2ds, "2D-S"), (wwr2dss, "2D-SS")])
def test_the_command_line_writes_the_file_compare_looks_for(clean_scene, tmp_path, cli, name):
    """The result file is named by the Method's name alone: the one the command line writes
    is the one the comparison looks up (found; stale, as it carries no provenance record)."""
    from metrics.run.methods import method_specs
    from metrics.run.runner import run_missing

    data = tmp_path / "bench"
    shutil.copytree(clean_scene, data / clean_scene.name)
    assert cli.main(["--views", "ideal", "--data", str(data)]) == 0
    written = sorted(default_results_folder(data).iterdir())
    specs = method_specs((name,), ("ideal",), default_results_folder(data))
    assert [s.method.name for s in specs] == [name]
    found = run_missing(find_scene_folders(data), specs, default_results_folder(data),
                        allow_run=False, log=lambda _: None)
    assert [o.path for o in found] == written and [o.status for o in found] == ["stale"]
    assert read_result(written[0]).method == name


@pytest.mark.slow
def test_without_data_the_default_benchmark_is_made_and_measured(tmp_path, monkeypatch, capsys):
    # The default benchmark, small: 64 px and 8 orbit views instead of 128 px and 40.
    default = partial(DefaultBenchmark, root=tmp_path / "cache", resolution=64, views=8,
                      workers=1)
    monkeypatch.setattr(baselines.cli, "DefaultBenchmark", default)
    assert wwr2dss.main(["--views", "multi"]) == 0
    out, err = capsys.readouterr()
    folder = default().folder
    assert f"no --data: the built-in 'tiny' benchmark in {folder} (generating it now)" in err
    scenes = find_scene_folders(folder)
    assert len(scenes) == 3
    for scene in scenes:
        result = read_result(default_results_folder(folder) / f"{scene.name}__2D-SS__multi.json")
        assert_table_shows(out, result)
    assert wwr2ds.main(["--views", "multi"]) == 0
    assert f"benchmark in {folder} (cached)" in capsys.readouterr().err
