"""Segmenters: every answer checked, names resolved, and a plugin from another package (the
worked example of docs/segment.md, read from the page) compared through metrics.compare."""

import contextlib
import io
import sys

import numpy as np
import pytest
from segment_plugin import doc_blocks, install_toy_plugin

from envelope.classes import NUM_CLASSES, SemanticClass
from metrics.compare import main
from metrics.report.tables import read_csv_rows
from segment.segmenter import (
    Segmenter,
    installed_segmenters,
    resolve_segmenter,
    segment_rgb,
)

RGB = np.zeros((6, 8, 3), np.uint8)


def _segmenter(fn) -> Segmenter:
    return Segmenter("test", fn, {})


def test_a_good_answer_passes_unchanged():
    labels = np.full((6, 8), SemanticClass.WINDOW, np.uint8)
    assert segment_rgb(_segmenter(lambda rgb: labels), RGB) is labels


@pytest.mark.parametrize("answer, message", [
    (np.zeros((8, 6), np.uint8), r"shape \(8, 6\) for an image of \(6, 8\)"),
    (np.zeros((6, 8, 1), np.uint8), r"shape \(6, 8, 1\)"),
    (np.zeros((6, 8), np.int64), "dtype int64"),
    (np.zeros((6, 8), bool), "dtype bool"),
    (np.full((6, 8), NUM_CLASSES, np.uint8), f"class id {NUM_CLASSES}; ids must be 0..5"),
    ([[0] * 8] * 6, "a list; it must return a numpy array"),
])
def test_a_wrong_answer_names_the_segmenter_and_the_fault(answer, message):
    with pytest.raises(ValueError, match=f"segmenter 'test' returned .*{message}"):
        segment_rgb(_segmenter(lambda rgb: answer), RGB)


@pytest.mark.parametrize("rgb", [np.zeros((6, 8), np.uint8), np.zeros((6, 8, 4), np.uint8),
                                 np.zeros((6, 8, 3), np.float32)])
def test_a_segmenter_is_only_given_uint8_rgb(rgb):
    with pytest.raises(ValueError, match=r"takes \(H, W, 3\) uint8 RGB"):
        segment_rgb(_segmenter(lambda x: np.zeros(x.shape[:2], np.uint8)), rgb)


def test_the_committed_weights_resolve_by_name():
    assert resolve_segmenter("photos", threads=1).name == "photos"
    assert resolve_segmenter("renders", threads=1).name == "renders"
    default = resolve_segmenter(None, threads=1)
    assert default.name == "renders" and default.identity == resolve_segmenter(
        "default", threads=1).identity


def test_unknown_names_list_what_is_there(tmp_path):
    with pytest.raises(ValueError, match=r"unknown segmenter 'nope'.*\(default, photos, renders"):
        resolve_segmenter("nope")
    with pytest.raises(ValueError, match="not found"):
        resolve_segmenter(str(tmp_path / "missing.pt"))
    with pytest.raises(ValueError, match="threads must be >= 1"):
        resolve_segmenter(None, threads=0)


def test_the_documented_example_is_20_lines_or_so():
    assert len(doc_blocks("python")[0].strip().splitlines()) <= 20


@pytest.mark.slow
def test_a_plugin_segmenter_is_found_checked_and_compared(tiny_benchmark, tmp_path, monkeypatch):
    name = install_toy_plugin(tmp_path / "site", monkeypatch)
    try:
        assert name in installed_segmenters()
        toy = resolve_segmenter(name)
        assert toy.identity["version"] == "0.1" and toy.identity["code"] != "absent"
        rgb = np.full((4, 5, 3), 30, np.uint8)
        assert (segment_rgb(toy, rgb) == SemanticClass.WINDOW).all()
        out = tmp_path / "out"
        argv = ["--data", str(tiny_benchmark), "--methods", "2D-S", "--views", "ideal",
                "--results", str(tmp_path / "results"), "--out", str(out),
                "--masks", f"predicted:{name}"]
        with contextlib.redirect_stdout(io.StringIO()):
            assert main(argv) == 0
        key = f"predicted-{name}"
        rows = read_csv_rows((tmp_path / f"out-masks-{key}" / "exact_vs_predicted.csv")
                             .read_text())
        per_building = [r for r in rows if not r["scene"].startswith("mean")]
        assert {r["scene"] for r in per_building} == {
            "tiny_skyscraper", "tiny_l_shaped", "realistic_house"}
        assert all(0 <= float(r["window_iou"]) <= 1 for r in per_building)
        assert all(r["wwr_ape_exact"] for r in per_building)
        # the toy's masks are poor: a run may fail (building pixels without depth), not all
        assert any(r["wwr_ape_predicted"] for r in per_building)
        # exact-mask results beside, the predicted-mask ones apart and naming the segmenter
        assert (tmp_path / "results" / "tiny_skyscraper__2D-S__ideal.json").is_file()
        result = (tmp_path / "results" / "masks" / key / "tiny_l_shaped__2D-S__ideal.json")
        assert f'"segmenter": "{name}"' in result.read_text()
    finally:
        sys.modules.pop("toy_masks_plugin", None)


def test_a_plugin_factory_is_called_once_and_a_broken_plugin_says_why(tmp_path, monkeypatch):
    factory = ("import numpy as np\n"
               "def make():\n"
               "    return lambda rgb: np.zeros(rgb.shape[:2], np.uint8)\n")
    name = install_toy_plugin(tmp_path / "a", monkeypatch, factory,
                              "factory-masks = toy_masks_plugin:make")
    assert (segment_rgb(resolve_segmenter(name), RGB) == 0).all()
    broken = install_toy_plugin(tmp_path / "b", monkeypatch, "raise ImportError('no torch')\n",
                                "broken-masks = toy_masks_plugin:segment")
    with pytest.raises(ValueError, match="broken-masks .* does not load: ImportError: no torch"):
        resolve_segmenter(broken)
    sys.modules.pop("toy_masks_plugin", None)
