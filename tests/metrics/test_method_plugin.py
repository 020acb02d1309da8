"""A method from another package, registered through the entry point, runs in metrics.compare.

The package is the worked example of docs/adding-a-method.md, read from the page.
"""

import contextlib
import io
import json
import re
import sys

import pytest
from paths import REPO_ROOT

from envelope.method import ENTRY_POINT_GROUP, installed_methods
from metrics.compare import main
from metrics.report.report import read_building_errors_csv
from metrics.report.tables import read_csv_rows

DOC = REPO_ROOT / "docs" / "adding-a-method.md"


def doc_blocks(language: str) -> list[str]:
    """The fenced code blocks of ``language`` in docs/adding-a-method.md, in order."""
    return re.findall(rf"```{language}\n(.*?)```", DOC.read_text(), flags=re.S)


def _install_toy_package(root, monkeypatch):
    """A throwaway distribution on sys.path: the documented module, and a dist-info with the
    documented entry point."""
    (root / "toy_wwr_plugin.py").write_text(doc_blocks("python")[0])
    (table,) = [b for b in doc_blocks("toml") if ENTRY_POINT_GROUP in b]
    info = root / "toy_wwr_plugin-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: toy-wwr-plugin\nVersion: 0.1\n")
    # pyproject's [project.entry-points."GROUP"] table with `name = "module:attr"` lines is
    # [GROUP] with `name = module:attr` lines in entry_points.txt
    entries = re.findall(r'^(\S+) = "(\S+)"$', table, flags=re.M)
    assert entries == [("toy", "toy_wwr_plugin:METHOD")]
    (info / "entry_points.txt").write_text(
        f"[{ENTRY_POINT_GROUP}]\n" + "".join(f"{k} = {v}\n" for k, v in entries))
    monkeypatch.syspath_prepend(str(root))


@pytest.mark.slow
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


@pytest.mark.slow
def test_a_plugin_declares_its_own_option(tiny_benchmark, tmp_path, monkeypatch, capsys):
    """The toy's ``--toy-noise`` is in ``--help`` and sets its config, as ``--set`` does."""
    (tmp_path / "site").mkdir()
    _install_toy_package(tmp_path / "site", monkeypatch)
    monkeypatch.setenv("COLUMNS", "200")  # argparse wraps the help at the terminal's width
    try:
        with pytest.raises(SystemExit) as stopped:
            main(["--help"])
        assert stopped.value.code == 0
        help_text = capsys.readouterr().out
        assert "toy options:" in help_text
        assert re.search(r"\n  --toy-noise NOISE +constant added to the WWR; default: 0\n",
                         help_text)

        def wwr_est(name: str, *extra: str) -> dict[str, float]:
            out = tmp_path / name
            with contextlib.redirect_stdout(io.StringIO()):
                assert main(["--data", str(tiny_benchmark), "--methods", "toy", "--views",
                             "ideal", "--results", str(tmp_path / "results"), "--out",
                             str(out), *extra]) == 0
            return {r.scene: r.wwr_est for r in read_building_errors_csv(out / "per_building.csv")}

        plain = wwr_est("plain")
        flagged = wwr_est("flagged", "--toy-noise", "0.25")
        both = wwr_est("both", "--toy-noise", "0.25", "--set", "toy.noise=0.5")  # --set wins
        assert len(plain) == 3
        assert flagged == pytest.approx({s: w + 0.25 for s, w in plain.items()}, abs=1e-12)
        assert both == pytest.approx({s: w + 0.5 for s, w in plain.items()}, abs=1e-12)
        provenance = json.loads((tmp_path / "both" / "provenance.json").read_text())
        assert provenance["methods"]["toy"]["config"] == {"noise": 0.5}
        capsys.readouterr()
        with pytest.raises(SystemExit) as stopped:
            main(["--methods", "toy", "--toy-noise", "lots"])
        assert stopped.value.code == 2
        assert "noise takes a number, got 'lots'" in capsys.readouterr().err
        assert main(["--data", str(tiny_benchmark), "--methods", "toy", "--no-run",
                     "--out", str(tmp_path / "o"), "--set", "toy.nosie=1"]) == 2
        err = capsys.readouterr().err
        assert err.startswith("error: --set toy.nosie=1: toy: ToyConfig has no field 'nosie'; "
                              "its fields: noise")
    finally:
        sys.modules.pop("toy_wwr_plugin", None)
