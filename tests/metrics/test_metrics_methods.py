"""Method wiring: names checked, configs recorded, read-only specs import nothing."""

from dataclasses import asdict

import pytest

from dataset.benchmark_cache import DefaultBenchmark
from metrics.robustness import RobustnessStudy
from metrics.run.methods import method_specs
from neural3d.method import Neural3dBudget


def test_specs_carry_the_configs_the_methods_run_with(tmp_path):
    from baselines.wwr2ds import Wwr2dsConfig
    from baselines.wwr2dss import Wwr2dssConfig
    from neural3d.config import preset_config

    specs = method_specs(("2D-S", "2D-SS", "neural3d"), ("ideal", "train"), tmp_path,
                         configs={"neural3d": Neural3dBudget(
                             preset="tiny", steps=300, max_minutes=1.5, resolution=96,
                             eval_frames=1)})
    s2ds, s2dss, n3d = specs
    assert (s2ds.protocols, s2ds.config) == (("ideal", "train"), asdict(Wwr2dsConfig()))
    assert s2dss.config == asdict(Wwr2dssConfig())
    assert n3d.protocols == ("train",) and n3d.has_footprint
    assert n3d.config["budget"] == {"preset": "tiny", "steps": 300, "max_seconds": 90.0,
                                    "threads": 2, "device": "cpu"}
    assert n3d.config["train"] == {**asdict(preset_config("tiny")), "eval_max_frames": 1,
                                   "iterations": 300}
    assert n3d.code == ("envelope", "neural3d") and s2dss.code == ("envelope", "baselines")
    assert n3d.config["resolution"] == 96  # matched against ExtractConfig.resolution
    # the whole extraction config keys the cache, so a result measured otherwise is redone
    from neural3d.extraction.extract_config import ExtractConfig
    from neural3d.extraction.measure_config import MeasureConfig

    assert n3d.config["measure"] == asdict(MeasureConfig())
    (default,) = method_specs(("neural3d",), (), tmp_path)
    assert default.config["resolution"] == ExtractConfig().resolution


def test_views_choose_the_protocols_each_method_declares(tmp_path):
    """``--views`` names protocols; a method runs on those of them it declares."""
    from envelope.protocols import DEFAULT_PROTOCOLS

    def protocols(views):
        return {s.name: s.protocols for s in method_specs(("2D-S", "neural3d"), views, tmp_path)}

    assert protocols(DEFAULT_PROTOCOLS) == {"2D-S": ("ideal", "multi", "train"),
                                            "neural3d": ("train",)}
    assert protocols(("train",)) == {"2D-S": ("train",), "neural3d": ("train",)}
    assert protocols(("street",)) == {"2D-S": ("street",), "neural3d": ("street",)}
    assert protocols(("street", "ideal")) == {"2D-S": ("ideal", "street"),
                                              "neural3d": ("street",)}


@pytest.mark.parametrize(
    ("names", "views", "message"),
    [(("2D-X",), ("ideal",), "unknown method '2D-X'"), ((), ("ideal",), "no method given"),
     (("2D-S",), ("ideal", "oblique"), "unknown views 'oblique'")],
)
def test_bad_names(tmp_path, names, views, message):
    with pytest.raises(ValueError, match=message):
        method_specs(names, views, tmp_path)


def test_budget_must_be_positive():
    with pytest.raises(ValueError, match="max minutes must be > 0"):
        Neural3dBudget(max_minutes=0)
    with pytest.raises(ValueError, match="steps must be >= 1"):
        Neural3dBudget(steps=0)
    with pytest.raises(ValueError, match="resolution must be >= 8"):
        Neural3dBudget(resolution=4)
    with pytest.raises(ValueError, match="eval frames must be >= 1"):
        Neural3dBudget(eval_frames=0)


def test_default_benchmark_announces_what_it_does(tmp_path):
    default = DefaultBenchmark(root=tmp_path)
    line = default.announce(("2D-S", "neural3d"), {"neural3d": 1000})
    assert f"to be generated in {tmp_path / 'tiny'}" in line
    assert "neural3d 1000 training steps per building" in line
    assert f"about {default.expected_minutes:g} minutes on 2 CPU cores" in line
    assert "neural3d" not in default.announce(("2D-S",), {}).split("methods")[1]
    study = RobustnessStudy()  # clean + one neural3d comparison per degradation
    assert study.heavy_comparisons == 5
    assert RobustnessStudy(heavy_levels="all").heavy_comparisons == 13
    line = default.announce(("2D-S", "neural3d"), {"neural3d": 1000}, study.heavy_comparisons)
    assert "5 comparisons" in line
    assert f"about {5 * default.expected_minutes:g} minutes" in line


def test_a_spec_is_its_method_bound_to_a_config(tmp_path):
    """The spec holds the Method and the config it runs with; what it says of the method is
    read off them (nothing copied that could disagree), and its results record its config."""
    from dataclasses import replace

    from envelope.method import built_in_method
    from envelope.results import read_result
    from envelope.scenes.scene import find_scene_folders
    from metrics.run.runner import folder_spec, run_missing
    from neural3d.method import record_config, reserve

    budget = Neural3dBudget(seed=2, threads=3)
    (n3d,) = method_specs(("neural3d",), ("ideal",), tmp_path, configs={"neural3d": budget},
                          seeds=(2,))
    method = built_in_method("neural3d")
    assert n3d.method is method and n3d.method_config == budget
    assert (n3d.name, n3d.paper_name, n3d.heavy) == (method.name, method.paper_name, True)
    assert (n3d.mesh_file, n3d.libraries) == (method.mesh_file, method.libraries)
    assert n3d.seed == 2 and n3d.artefacts_dir == tmp_path / "neural3d_runs" / "seed2"
    assert (n3d.resources.cpus, n3d.resources.gpus) == reserve(budget) == (3.0, 0.0)
    assert n3d.config == record_config(budget)
    renamed = replace(n3d, method=replace(method, name="neural3d-b", paper_name=None))
    assert (renamed.name, renamed.paper_name) == ("neural3d-b", None)

    (data := tmp_path / "data" / "a").mkdir(parents=True)
    (data / "building.json").write_text("{}")

    def run(scene_dir, protocol):
        from metrics_helpers import make_result

        return replace(make_result("a", "fake", protocol, 0.5), config={"made": "by the run"})

    spec = replace(folder_spec("fake", ("ideal",), {"k": 1}, run), conditions={"masks": "x"})
    assert spec.config == {"k": 1, "masks": "x"} and spec.seed is None
    (outcome,) = run_missing(find_scene_folders(data), [spec], tmp_path / "results", log=print)
    assert read_result(outcome.path).config == {"k": 1, "masks": "x"}
