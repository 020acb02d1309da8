"""baselines.cli and both CLIs on the tiny benchmark (fixture from conftest)."""

import pytest

from baselines import wwr2ds, wwr2dss
from baselines.cli import default_results_folder, scene_folders
from dataset.core.results import read_result
from dataset.core.truth import read_building


def test_scene_folders_and_default_results_folder(tmp_path):
    for name in ("b", "a"):
        (tmp_path / "bench" / name).mkdir(parents=True)
        (tmp_path / "bench" / name / "transforms.json").write_text("{}")
    (tmp_path / "bench" / "notes").mkdir()
    bench = tmp_path / "bench"
    assert [p.name for p in scene_folders(bench)] == ["a", "b"]
    assert scene_folders(bench / "a") == [bench / "a"]
    assert default_results_folder(bench) == tmp_path / "results"
    assert default_results_folder(bench / "a") == tmp_path / "results"
    with pytest.raises(ValueError, match="neither a scene folder"):
        scene_folders(bench / "notes")
    with pytest.raises(ValueError, match="does not exist"):
        scene_folders(tmp_path / "nowhere")


@pytest.mark.slow
@pytest.mark.parametrize("views", ["ideal", "multi"])
def test_both_clis_on_the_tiny_benchmark(tiny_benchmark, tmp_path, views):
    out = tmp_path / "results"
    assert wwr2ds.main(["--views", views, "--data", str(tiny_benchmark), "--out", str(out)]) == 0
    assert wwr2dss.main(["--views", views, "--data", str(tiny_benchmark), "--out", str(out),
                         "--debug-images", str(tmp_path / "dbg")]) == 0
    scenes = scene_folders(tiny_benchmark)
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
