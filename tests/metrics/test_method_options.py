"""Methods own their options: typed values from text, ``--set METHOD.KEY=VALUE``, the order
in which a config is built, and the comparison's one-line errors."""

import argparse
import contextlib
import io
import json
from dataclasses import dataclass

import pytest
from metrics_helpers import make_benchmark

from baselines.facade_mask import PlaneIsolationConfig
from baselines.wwr2dss import Wwr2dssConfig
from envelope.method import Method, available_methods
from envelope.method_options import Option, parse_value, with_settings
from envelope.protocols import VIEW_PROTOCOLS
from metrics.compare import main
from metrics.run.compare_args import compare_request, parse_compare_args
from metrics.run.method_args import add_method_options, parse_sets
from neural3d.method import SHORT_RUN, Neural3dBudget


@pytest.fixture(scope="module")
def methods():
    return available_methods()


def test_values_are_read_by_the_field_type():
    assert parse_value(Wwr2dssConfig, "max_rectified_px", "512") == 512
    assert parse_value(Wwr2dssConfig, "rectified_scale", "0.5") == 0.5
    assert parse_value(Wwr2dssConfig, "weighting", "area") == "area"
    assert parse_value(Wwr2dssConfig, "isolation.wall_tolerance_m", "0.1") == 0.1
    assert parse_value(Neural3dBudget, "steps", "none") is None
    assert parse_value(Neural3dBudget, "steps", "300") == 300
    assert parse_value(Neural3dBudget, "preset", "tiny") == "tiny"


@pytest.mark.parametrize(
    ("config_type", "key", "text", "message"),
    [(Wwr2dssConfig, "max_rectified_px", "1.5", "max_rectified_px takes an integer, got '1.5'"),
     (Wwr2dssConfig, "weighting", "volume", "weighting takes one of alpha, area, got 'volume'"),
     (Neural3dBudget, "steps", "many", "steps takes an integer or none, got 'many'"),
     (Neural3dBudget, "stepz", "1", "Neural3dBudget has no field 'stepz'; its fields: preset, "
      "steps, max_minutes, threads, resolution, eval_frames, device"),
     (Wwr2dssConfig, "isolation", "1", "isolation is a nested config (PlaneIsolationConfig)"),
     (Wwr2dssConfig, "isolation.depth", "1", "PlaneIsolationConfig has no field 'depth'"),
     (Wwr2dssConfig, "seed.bits", "1", "'seed' (an integer) is not a dataclass")],
)
def test_a_bad_key_or_value_says_what_is_allowed(config_type, key, text, message):
    with pytest.raises(ValueError, match="^" + message.replace("(", r"\(").replace(")", r"\)")):
        parse_value(config_type, key, text)


def test_settings_reach_nested_configs_and_run_their_checks():
    config = with_settings(Wwr2dssConfig(), {"weighting": "area", "isolation.fit_stride": 2,
                                             "isolation.wall_tolerance_m": 0.1})
    assert config == Wwr2dssConfig(weighting="area", isolation=PlaneIsolationConfig(
        fit_stride=2, wall_tolerance_m=0.1))
    assert with_settings(config, {}) is config
    with pytest.raises(ValueError, match="wall_tolerance_m must be > 0"):
        with_settings(Wwr2dssConfig(), {"isolation.wall_tolerance_m": -1.0})


def test_a_method_refuses_options_its_config_lacks():
    @dataclass(frozen=True)
    class Config:
        noise: float = 0.0

    def make(**fields):
        return Method(name="m", inputs=("semantics",), protocols=VIEW_PROTOCOLS,
                      config_type=Config, run=lambda *a: None, **fields)

    assert make(options=(Option("--m-noise", "noise", "noise"),)).options[0].key == "noise"
    with pytest.raises(ValueError, match="method m: option or short-run setting 'nois'"):
        make(options=(Option("--m-noise", "nois", "noise"),))
    with pytest.raises(ValueError, match="short-run setting 'steps'"):
        make(short_run={"steps": 3})
    with pytest.raises(ValueError, match="must look like --name"):
        Option("m-noise", "noise", "noise")


def test_a_flag_taken_already_is_skipped_with_a_warning(methods):
    @dataclass(frozen=True)
    class Config:
        data: str = ""

    clash = Method(name="clash", inputs=("semantics",), protocols=VIEW_PROTOCOLS,
                   config_type=Config, run=lambda *a: None,
                   options=(Option("--data", "data", "x"),))
    parser = argparse.ArgumentParser()
    parser.add_argument("--data")
    said = []
    add_method_options(parser, {"clash": clash}, warn=said.append)
    assert said == ["option --data of method clash skipped: argument --data: conflicting "
                    "option string: --data"]


@pytest.mark.parametrize(
    ("text", "message"),
    [("2D-SS", "--set '2D-SS': expected METHOD.KEY=VALUE"),
     ("magic.x=1", "--set magic.x=1: no method 'magic'; choose from 2D-S, 2D-SS, neural3d"),
     ("2D-SS.weighting=volume", "--set 2D-SS.weighting=volume: 2D-SS: weighting takes one of"),
     ("neural3d.stepz=3", "--set neural3d.stepz=3: neural3d: Neural3dBudget has no field")],
)
def test_set_errors_name_what_was_wrong(methods, text, message):
    with pytest.raises(ValueError, match="^" + message.replace(".", r"\.")):
        parse_sets([text], methods)


def test_a_config_is_default_then_short_run_then_flags_then_set(methods, tmp_path):
    def neural3d(*argv):
        args = parse_compare_args(["--no-run", "--methods", "neural3d", *argv], methods)
        return compare_request(args, methods).configs["neural3d"]

    data = ["--data", str(tmp_path)]
    assert neural3d(*data) == Neural3dBudget()
    assert neural3d() == Neural3dBudget(**SHORT_RUN)  # the built-in default run
    assert neural3d(*data, "--robustness") == Neural3dBudget(**SHORT_RUN)
    assert neural3d("--neural3d-steps", "50", "--device", "cuda:3") == Neural3dBudget(
        **{**SHORT_RUN, "steps": 50, "device": "cuda:3"})
    assert neural3d("--neural3d-steps", "50", "--set", "neural3d.steps=none", "--set",
                    "neural3d.eval_frames=4") == Neural3dBudget(
        **{**SHORT_RUN, "steps": None, "eval_frames": 4})
    assert neural3d(*data, "--set", "neural3d.steps=7", "--set", "neural3d.steps=8").steps == 8


@pytest.mark.slow
def test_set_configs_are_what_the_comparison_records(tmp_path):
    data, results = make_benchmark(tmp_path)
    out = tmp_path / "out"
    argv = ["--data", str(data), "--results", str(results), "--out", str(out), "--no-run",
            "--views", "ideal", "--set", "2D-SS.weighting=area", "--set",
            "2D-SS.isolation.fit_stride=2", "--neural3d-steps", "300", "--neural3d-preset",
            "tiny"]
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        assert main(argv) == 0
    configs = {k: v["config"] for k, v in
               json.loads((out / "provenance.json").read_text())["methods"].items()}
    assert configs["2D-SS"]["weighting"] == "area"
    assert configs["2D-SS"]["isolation"]["fit_stride"] == 2
    assert configs["2D-S"]["combine"] == "mean"
    assert configs["neural3d"]["budget"]["steps"] == 300
    assert configs["neural3d"]["budget"]["preset"] == "tiny"


@pytest.mark.parametrize(
    ("args", "message"),
    [(["--set", "neural3d.steps=0"], "neural3d steps must be >= 1, got 0"),
     (["--set", "neural3d.stepz=3"], "Neural3dBudget has no field 'stepz'"),
     (["--set", "2D-SS.weighting=volume"], "weighting takes one of alpha, area"),
     (["--set", "magic.x=1"], "no method 'magic'")],
)
def test_a_bad_set_is_one_line_and_exit_code_2(tmp_path, capsys, args, message):
    data, _ = make_benchmark(tmp_path)
    assert main(["--data", str(data), "--out", str(tmp_path / "o"), "--no-run", *args]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and message in err and err.count("\n") == 1
    assert not (tmp_path / "o").exists()


def test_modes_exclude_each_other(capsys):
    with pytest.raises(SystemExit) as stopped:
        main(["--robustness", "--degrade", "pose:0.3"])
    assert stopped.value.code == 2
    assert "not allowed with argument" in capsys.readouterr().err


def test_explain_uses_the_explained_methods_options(methods, tmp_path, capsys):
    data, results = make_benchmark(tmp_path)
    base = ["--data", str(data), "--results", str(results), "--methods", "2D-S"]
    argv = [*base, "--explain", "sky_a", "neural3d", "--neural3d-steps", "300"]
    request = compare_request(parse_compare_args(argv, methods), methods)
    assert request.methods == ("neural3d",)
    assert request.configs == {"neural3d": Neural3dBudget(steps=300)}
    assert (request.results, request.out) == (results, data.with_name("data-compare"))
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert text.startswith(f"# sky_a / neural3d / train: {results}/sky_a__neural3d__train.json")
    assert main([*base, "--explain", "nowhere", "2D-S"]) == 2
    assert "error: no scene 'nowhere' in" in capsys.readouterr().err
