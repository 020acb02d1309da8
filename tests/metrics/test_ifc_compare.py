"""An imported IFC house goes through the benchmark: ``dataset.generate --ifc`` then
``metrics.compare --data`` runs 2D-S, 2D-SS and neural3d on it (tiny images; neural3d's
``tiny`` preset, whose 150 steps end the training, not the generous time limit) and writes
Table 2 and Table 3 rows for the ``imported`` family (~30-60 s on 2 cores).
"""

import contextlib
import io

import pytest

from dataset import generate
from dataset.examples.ifc_houses import box_house
from metrics.compare import main as compare
from metrics.report.tables import read_csv_rows


@pytest.mark.slow
def test_methods_run_on_an_imported_ifc_scene(tmp_path):
    box_house(tmp_path / "house.ifc")
    data = tmp_path / "data"
    assert generate.main(["--ifc", str(tmp_path / "house.ifc"), "--out", str(data),
                          "--views", "8", "--resolution", "48", "--quiet"]) == 0
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        code = compare(["--data", str(data), "--methods", "2D-S,2D-SS,neural3d",
                        "--views", "ideal,train", "--neural3d-preset", "tiny",
                        "--neural3d-steps", "150", "--neural3d-resolution", "32",
                        "--out", str(tmp_path / "out")])
    assert code == 0
    rows = read_csv_rows((tmp_path / "out" / "table2_errors.csv").read_text())
    got = {(r["family"], r["method"], r["protocol"]): r for r in rows}
    for key in (("imported", m, "ideal") for m in ("2D-S", "2D-SS")):
        assert (got[key]["buildings"], got[key]["failed"]) == ("1", "0"), key
        assert got[key]["wwr_ape_mean"] != ""
        # on ideal views the 2D methods see the house's true facades: area within 5 %
        assert float(got[key]["facade_ape_mean"]) < 5.0, key
    for key in (("imported", m, "train") for m in ("2D-S", "2D-SS", "neural3d")):
        assert (got[key]["buildings"], got[key]["failed"]) == ("1", "0"), key
        assert got[key]["wwr_ape_mean"] != ""
    t3 = read_csv_rows((tmp_path / "out" / "table3_footprint_iou.csv").read_text())
    assert any(r["family"] == "imported" and r["failed"] == "0" for r in t3)
