"""A method from another package, registered through the entry point, runs in metrics.compare."""

import contextlib
import io
import sys
import textwrap

from dataset.core.method import ENTRY_POINT_GROUP, installed_methods
from metrics.compare import main
from metrics.tables import read_csv_rows

TOY_MODULE = '''
"""A toy WWR method: window / facade pixels of the semantic masks, nothing else."""
from dataclasses import dataclass

import numpy as np

from dataset.core.classes import SemanticClass
from dataset.scenes.images import read_labels
from dataset.core.method import Method
from dataset.core.results import MethodResult
from dataset.core.wwr import wwr_from_areas


@dataclass(frozen=True)
class ToyConfig:
    noise: float = 0.0


def run(scene, protocol, config):
    counts = np.zeros(3)
    for frame in scene.frames_in(protocol):
        labels = read_labels(scene.path(frame.semantic_file_path))
        counts += [(labels == c).sum() for c in
                   (SemanticClass.WINDOW, SemanticClass.WALL, SemanticClass.DOOR)]
    wwr = wwr_from_areas(*counts) + config.noise
    return MethodResult(scene=scene.root.name, method="toy", protocol=protocol, wwr=wwr,
                        window_area_m2=None, facade_area_m2=None)


METHOD = Method(name="toy", inputs=("semantics",), protocols=("ideal", "multi"),
                config_type=ToyConfig, run=run, packages=("toy_wwr_plugin",))
'''


def _install_toy_package(root, monkeypatch):
    """A throwaway distribution on sys.path: a module and its dist-info with the entry point."""
    (root / "toy_wwr_plugin.py").write_text(TOY_MODULE)
    info = root / "toy_wwr_plugin-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: toy-wwr-plugin\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(textwrap.dedent(f"""
        [{ENTRY_POINT_GROUP}]
        toy = toy_wwr_plugin:METHOD
    """))
    monkeypatch.syspath_prepend(str(root))


def test_a_plugin_method_is_listed_and_compared(tiny_benchmark, tmp_path, monkeypatch):
    (tmp_path / "site").mkdir()
    _install_toy_package(tmp_path / "site", monkeypatch)
    try:
        assert "toy" in installed_methods()
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            assert main(["--list-methods"]) == 0
        assert any(line.startswith("toy") and "plugin" in line and "semantics" in line
                   for line in buf.getvalue().splitlines())
        out = tmp_path / "out"
        argv = ["--data", str(tiny_benchmark), "--methods", "2D-S,toy", "--views", "ideal",
                "--results", str(tmp_path / "results"), "--out", str(out)]
        with contextlib.redirect_stdout(io.StringIO()):
            assert main(argv) == 0
        rows = read_csv_rows((out / "table2_errors.csv").read_text())
        toy = {r["family"]: r for r in rows if r["method"] == "toy"}
        assert set(toy) == {"skyscraper", "l_shaped", "realistic", "all"}
        assert all(r["failed"] == "0" and r["wwr_ape_mean"] != "" for r in toy.values())
        per_building = read_csv_rows((out / "per_building.csv").read_text())
        assert sum(r["method"] == "toy" for r in per_building) == 3
        assert (out / "plots" / "wwr_scatter.png").is_file()
        assert (tmp_path / "results" / "tiny_skyscraper__toy__ideal.json").is_file()
    finally:
        sys.modules.pop("toy_wwr_plugin", None)
