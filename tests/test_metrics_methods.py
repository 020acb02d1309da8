"""Method wiring: names checked, configs recorded, read-only specs import nothing."""

from dataclasses import asdict
from pathlib import Path

import pytest

from metrics.benchmark_cache import DefaultBenchmark
from metrics.methods import Neural3dBudget, method_specs, read_only_specs


def test_specs_carry_the_configs_the_methods_run_with(tmp_path):
    from baselines.wwr2ds import Wwr2dsConfig
    from baselines.wwr2dss import Wwr2dssConfig
    from neural3d.config import preset_config

    specs = method_specs(("2D-S", "2D-SS", "neural3d"), ("ideal",), tmp_path,
                         neural3d=Neural3dBudget(preset="tiny", minutes=1.5, resolution=96,
                                                 eval_frames=1))
    s2ds, s2dss, n3d = specs
    assert (s2ds.protocols, s2ds.config) == (("ideal",), asdict(Wwr2dsConfig()))
    assert s2dss.config == asdict(Wwr2dssConfig())
    assert n3d.protocols == ("train",) and n3d.has_footprint
    assert n3d.config["budget"] == {"preset": "tiny", "max_seconds": 90.0}
    assert n3d.config["train"] == {**asdict(preset_config("tiny")), "eval_max_frames": 1}
    assert n3d.config["resolution"] == 96  # matched against ExtractConfig.resolution
    # a stored result meshed or measured another way is not reused (runner.config_matches)
    from metrics.runner import config_matches
    from neural3d.extract_config import ExtractConfig
    from neural3d.measure import MeasureConfig

    assert n3d.config["measure"] == asdict(MeasureConfig())
    assert config_matches(n3d.config, {**n3d.config, "extra_key": 1})
    assert not config_matches(n3d.config, {**n3d.config,
                                           "measure": asdict(MeasureConfig(count="all"))})
    assert not config_matches(n3d.config, {**n3d.config, "footprint_heights_m": [1.0]})
    (default,) = method_specs(("neural3d",), (), tmp_path)
    assert default.config["resolution"] == ExtractConfig().resolution


def test_read_only_specs_never_run():
    (spec,) = read_only_specs(("neural3d",), ("ideal", "multi"))
    assert spec.protocols == ("train",) and spec.config == {} and spec.has_footprint
    with pytest.raises(RuntimeError, match="read-only"):
        spec.run(Path("."), "train")


@pytest.mark.parametrize(
    ("names", "views", "message"),
    [(("2D-X",), ("ideal",), "unknown method '2D-X'"), ((), ("ideal",), "no method given"),
     (("2D-S",), ("ideal", "oblique"), "unknown views 'oblique'")],
)
def test_bad_names(tmp_path, names, views, message):
    with pytest.raises(ValueError, match=message):
        method_specs(names, views, tmp_path)
    with pytest.raises(ValueError, match=message):
        read_only_specs(names, views)


def test_budget_must_be_positive():
    with pytest.raises(ValueError, match="minutes must be > 0"):
        Neural3dBudget(minutes=0)
    with pytest.raises(ValueError, match="resolution must be >= 8"):
        Neural3dBudget(resolution=4)
    with pytest.raises(ValueError, match="eval frames must be >= 1"):
        Neural3dBudget(eval_frames=0)


def test_default_benchmark_announces_what_it_does(tmp_path):
    default = DefaultBenchmark(root=tmp_path)
    line = default.announce(("2D-S", "neural3d"), 2.0)
    assert f"to be generated in {tmp_path / 'tiny'}" in line
    assert "neural3d 2 min per building" in line and "about 10 minutes on 2 CPU cores" in line
    assert "neural3d" not in default.announce(("2D-S",), 2.0).split("methods")[1]
