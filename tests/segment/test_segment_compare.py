"""The protocol's hook in metrics.compare: --masks options, refusals, nothing cached on bad
input, and the exact-vs-predicted table."""

import contextlib
import io
import shutil
import sys
from dataclasses import replace
from pathlib import Path

import pytest
from segment_plugin import install_toy_plugin

from metrics.compare import main
from metrics.predicted_masks import exact_vs_predicted_table
from metrics.run.predicted_masks import MasksRequest, masks_key, parse_masks, splits_read
from metrics.run.runner import folder_spec
from metrics.score.errors import BuildingErrors
from segment.evaluate import SceneIou
from segment.segmenter import Segmenter


def test_masks_text_is_parsed_or_refused():
    assert parse_masks("predicted") == MasksRequest(None, 2)
    assert parse_masks("predicted:my.pt", threads=1) == MasksRequest("my.pt", 1)
    for bad in ("exact", "predicted:", "predict", ""):
        with pytest.raises(ValueError, match="write 'predicted' or 'predicted:MODEL'"):
            parse_masks(bad)


def test_keys_name_the_segmenter_and_its_weights():
    assert masks_key(Segmenter("default", len, {"weights": "0123456789abcdef"})) == (
        "predicted-default-01234567")
    assert masks_key(Segmenter("/x/my weights.pt", len, {"weights": "ab" * 8})) == (
        "predicted-my_weights-abababab")
    assert masks_key(Segmenter("toy-masks", len, {"entry_point": "x"})) == "predicted-toy-masks"


def test_only_the_splits_the_methods_read_are_segmented():
    def spec(*protocols, trained=False):
        made = folder_spec("m", protocols, {}, run=len)
        return replace(made, artefacts_dir=Path("runs")) if trained else made

    assert splits_read([spec("ideal", "multi")]) == ("ideal", "multi")
    # the held-out orbit views only for a trained method (a run folder) on the orbit
    assert splits_read([spec("ideal", "train")]) == ("ideal", "train")
    assert splits_read([spec("ideal"), spec("train", trained=True)]) == (
        "eval", "ideal", "train")
    assert splits_read([spec("ideal", trained=True), spec("train")]) == ("ideal", "train")
    assert splits_read([]) == ()


def _rows(scene, family, wwr, window, facade):
    return BuildingErrors(scene, family, "2D-S", "ideal", wwr_ape=wwr, window_ape=window,
                          facade_ape=facade)


def test_the_table_puts_exact_and_predicted_side_by_side_with_family_means():
    exact = [_rows("a", "skyscraper", 1.0, 2.0, 3.0), _rows("b", "skyscraper", 3.0, 4.0, 5.0)]
    predicted = [_rows("a", "skyscraper", 10.0, 20.0, 30.0),
                 BuildingErrors("b", "skyscraper", "2D-S", "ideal", status="failed")]
    ious = [SceneIou("a", "skyscraper", 4, _confusion(0.5)),
            SceneIou("b", "skyscraper", 4, _confusion(0.7))]
    table = exact_vs_predicted_table(exact, predicted, ious, "default")
    rows = {r[0]: r for r in table.rows}
    assert rows["a"][2:] == (0.5, "2D-S", "ideal", 1.0, 10.0, 2.0, 20.0, 3.0, 30.0)
    assert rows["b"][5:] == (3.0, None, 4.0, None, 5.0, None)  # a failed run: no figure
    mean = rows["mean (2)"]
    assert mean[1] == "skyscraper" and mean[2] == pytest.approx(0.6)
    assert mean[5:] == (2.0, 10.0, 3.0, 20.0, 4.0, 30.0)


def _confusion(window_iou):
    """A confusion matrix whose window IoU is ``window_iou`` (out of 10 px)."""
    import numpy as np

    c = np.zeros((6, 6), np.int64)
    hit = round(10 * window_iou)
    c[2, 2], c[2, 1] = hit, 10 - hit
    return c


@pytest.fixture()
def one_scene(clean_scene, tmp_path):
    data = tmp_path / "data"
    shutil.copytree(clean_scene, data / clean_scene.name)
    return data


def _run(argv, capsys):
    with contextlib.redirect_stdout(io.StringIO()):
        code = main(argv)
    return code, capsys.readouterr().err


def test_bad_masks_options_are_refused_before_anything_runs(one_scene, tmp_path, capsys):
    base = ["--data", str(one_scene), "--methods", "2D-S", "--views", "ideal",
            "--results", str(tmp_path / "r"), "--out", str(tmp_path / "o")]
    code, err = _run([*base, "--masks", "exact"], capsys)
    assert code == 2 and "write 'predicted' or 'predicted:MODEL'" in err
    code, err = _run([*base, "--masks", f"predicted:{tmp_path / 'missing.pt'}"], capsys)
    assert code == 2 and "not found" in err
    corrupt = tmp_path / "corrupt.pt"
    corrupt.write_bytes(b"\x00" * 100)
    code, err = _run([*base, "--masks", f"predicted:{corrupt}"], capsys)
    assert code == 2 and "not a readable segmenter weights file" in err
    with pytest.raises(SystemExit) as exit_info:  # the comparison's modes exclude each other
        _run([*base, "--masks", "predicted", "--degrade", "mask_noise"], capsys)
    assert exit_info.value.code == 2 and "not allowed with argument" in capsys.readouterr().err
    code, err = _run([*base, "--masks", "predicted", "--masks-threads", "0"], capsys)
    assert code == 2 and "--masks-threads must be >= 1" in err
    assert not (tmp_path / "data-masks").exists() and not (tmp_path / "r").exists()


@pytest.mark.slow
def test_a_plugin_with_wrong_answers_stops_the_run_and_leaves_no_masks(one_scene, tmp_path,
                                                                       monkeypatch, capsys):
    source = "import numpy as np\ndef segment(rgb):\n    return np.zeros((3, 3), np.uint8)\n"
    name = install_toy_plugin(tmp_path / "site", monkeypatch, source,
                              "bad-masks = toy_masks_plugin:segment")
    try:
        code, err = _run(["--data", str(one_scene), "--methods", "2D-S", "--views", "ideal",
                          "--results", str(tmp_path / "r"), "--out", str(tmp_path / "o"),
                          "--masks", f"predicted:{name}"], capsys)
    finally:
        sys.modules.pop("toy_masks_plugin", None)
    assert code == 2 and "segmenter 'bad-masks' returned shape (3, 3)" in err
    cache = tmp_path / "data-masks" / "predicted-bad-masks"
    assert not cache.exists() or list(cache.iterdir()) == []
    assert not (tmp_path / "r" / "masks").exists()


def test_a_method_on_predicted_masks_still_travels_to_another_process(one_scene, tmp_path):
    """The spec on predicted masks pickles (the processes and Ray executors send it to
    another process), runs there as the method does, and its results record the segmenter."""
    import pickle
    from dataclasses import replace

    from envelope.results import read_result
    from metrics.run.methods import method_specs
    from metrics.run.predicted_masks import CONFIG_KEY, with_predicted_masks
    from metrics.run.runner import run_missing

    spec = method_specs(("2D-S",), ("ideal",), tmp_path / "results")[0]
    scene = next(one_scene.iterdir())
    segmenter = Segmenter("toy", lambda rgb: rgb[..., 0] * 0, {"weights": "abc"})
    wrapped = with_predicted_masks([spec], segmenter)[0]
    travelled = pickle.loads(pickle.dumps(wrapped))
    assert travelled.config == {**spec.config,
                                CONFIG_KEY: {"segmenter": "toy", "weights": "abc"}}
    assert replace(travelled.run(scene, "ideal"), wall_time_s=0.0) == replace(
        spec.run(scene, "ideal"), wall_time_s=0.0)
    (outcome,) = run_missing([scene], [travelled], tmp_path / "masks", log=lambda _: None)
    assert read_result(outcome.path).config == travelled.config


@pytest.mark.slow
def test_neural3d_trains_on_predicted_masks_in_processes_of_its_own(tiny_benchmark, tmp_path):
    """`--masks predicted` with the processes executor (the default `auto` picks it when two
    trainings fit): every building gets a neural3d result on exact and on predicted masks."""
    import subprocess

    results = tmp_path / "results"
    done = subprocess.run(
        [sys.executable, "-m", "metrics.compare", "--data", str(tiny_benchmark),
         "--methods", "neural3d", "--neural3d-preset", "tiny", "--neural3d-steps", "20",
         "--neural3d-resolution", "24", "--neural3d-threads", "1", "--masks", "predicted",
         "--masks-threads", "1", "--executor", "processes", "--cpus", "2",
         "--results", str(results), "--out", str(tmp_path / "out")],
        capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    assert "failed" not in done.stdout
    assert len(list(results.glob("*__neural3d__train.json"))) == 3
    predicted = list((results / "masks").glob("*/*__neural3d__train.json"))
    assert len(predicted) == 3, done.stdout[-2000:]
