"""metrics.export.command: the box of tests/export_box.py (walls turned 30 degrees, north stated as
20)
gives its bins and per-orientation WWR in every format; WWR 0 stays 0 everywhere; the CityJSON
passes the official schema and cjval's other checks (tests/cityjson_checks.py).

Tolerances: figures are written rounded to 1e-6 (DECIMALS); CityJSON vertices to 1 mm, so
areas measured back from its polygons agree within 1e-3 relative.
"""

import csv
import json
import math

import numpy as np
import pytest
from cityjson_checks import cityjson_errors
from export_box import AZIMUTH_DEG, EXPECTED, box_truth, ideal_result, located_result

from envelope.orientation import BIN_NAMES, CONVENTIONS, ORIENTATION_BINS, orientation_bin
from envelope.results import write_result
from envelope.truth import write_building
from metrics.export.command import FORMATS, ExportInputs, export, main

BINS = ORIENTATION_BINS
# The ideal result on the truth's facades: facade 1 (W) 0.15, 2 (S) 0, 3 (E) 0.25, 4 (N) missing.
IDEAL = {"N": None, "E": 0.25, "S": 0.0, "W": 0.15}
# The located result: its facades lie on the truth's 3 (E, 0.28) and 2 (S, 0); none N or W.
LOCATED = {"N": None, "E": 0.28, "S": 0.0, "W": None}
WANTED = {("truth", ""): {b: EXPECTED[b][2] for b in BINS}, ("2D-SS", "ideal"): IDEAL,
          ("neural3d", "train"): LOCATED}


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    out = tmp_path_factory.mktemp("export")
    inputs = ExportInputs({"box": box_truth()}, (ideal_result(), located_result()))
    export(inputs, out, FORMATS)
    return out


def _csv_rows(path):
    lines = path.read_text().splitlines()
    header = [line for line in lines if line.startswith("#")]
    return header, list(csv.DictReader(line for line in lines if not line.startswith("#")))


def _num(text):
    return None if text in ("", None) else float(text)


def test_truth_facades_face_their_stated_bins():
    truth = box_truth()
    for f in truth.facades:
        assert f.azimuth_deg == pytest.approx(AZIMUTH_DEG[f.id])
    assert {f.orientation for f in truth.facades} == set(BINS)


def test_every_file_states_the_conventions_and_north(exported):
    for name in ("facades.csv", "orientations.csv", "energyplus_wwr.csv",
                 "cea_architecture.csv"):
        header, _ = _csv_rows(exported / name)
        assert [line[2:] for line in header[1:1 + len(CONVENTIONS)]] == list(CONVENTIONS)
        assert "# north of box: 20 deg (user)" in header
    for name in ("geomeppy.json", "honeybee.json", "teaser.json"):
        meta = json.loads((exported / name).read_text())["metadata"]
        assert meta["conventions"] == list(CONVENTIONS)
        assert meta["north"] == {"box": {"north_deg": 20.0, "north_source": "user"}}
    for path in (exported / "cityjson").glob("*.city.json"):
        attributes = json.loads(path.read_text())["CityObjects"]["box"]["attributes"]
        assert attributes["conventions"] == list(CONVENTIONS)
        assert attributes["north_deg"] == 20.0


def test_facades_csv_has_azimuth_bin_and_areas(exported):
    _, rows = _csv_rows(exported / "facades.csv")
    truth = {int(r["facade"]): r for r in rows if r["method"] == "truth"}
    for fid, azimuth in AZIMUTH_DEG.items():
        assert float(truth[fid]["azimuth_deg"]) == pytest.approx(azimuth, abs=1e-6)
        assert truth[fid]["orientation"] == orientation_bin(azimuth)
        r = truth[fid]
        assert float(r["gross_m2"]) == pytest.approx(
            float(r["wall_m2"]) + float(r["window_m2"]) + float(r["door_m2"]), abs=1e-5)
    assert truth[2]["wwr"] == "0.0" and truth[2]["window_m2"] == "0.0"
    ideal = {int(r["facade"]): r for r in rows if r["method"] == "2D-SS"}
    assert ideal[1]["azimuth_from"] == "truth facade" and ideal[1]["orientation"] == "W"
    assert ideal[2]["wwr"] == "0.0"  # an estimated WWR of 0 is 0, not empty
    assert ideal[4]["wwr"] == "" and "no usable view" in ideal[4]["note"]
    assert ideal[1]["wall_m2"] == "" and ideal[1]["door_m2"] == ""  # methods do not split doors
    located = {int(r["facade"]): r for r in rows if r["method"] == "neural3d"}
    assert located[7]["azimuth_from"] == "estimate normal" and located[7]["orientation"] == "E"


def _by_method(rows, value):
    out = {}
    for r in rows:
        out.setdefault((r["method"], r["protocol"]), {})[r["orientation"]] = value(r)
    return out


def test_orientations_csv(exported):
    _, rows = _csv_rows(exported / "orientations.csv")
    got = _by_method(rows, lambda r: _num(r["wwr"]))
    for key, wanted in WANTED.items():
        for b in BINS:
            assert got[key][b] == (None if wanted[b] is None else pytest.approx(wanted[b],
                                                                                abs=1e-6))
    truth = {r["orientation"]: r for r in rows if r["method"] == "truth"}
    for b, (gross, window, _) in EXPECTED.items():
        assert float(truth[b]["gross_m2"]) == pytest.approx(gross)
        assert float(truth[b]["window_m2"]) == pytest.approx(window)
    assert float(truth["E"]["door_m2"]) == pytest.approx(2.1)  # the door: gross, not net
    assert float(truth["E"]["wall_m2"]) == pytest.approx(90.0 - 27.0 - 2.1)
    missing = {r["orientation"]: r for r in rows if r["method"] == "2D-SS"}["N"]
    assert (missing["facades"], missing["missing"], missing["wwr"]) == ("1", "1", "")


def test_energyplus_table(exported):
    _, rows = _csv_rows(exported / "energyplus_wwr.csv")
    columns = dict(zip(BINS, ("North (315 to 45 deg)", "East (45 to 135 deg)",
                              "South (135 to 225 deg)", "West (225 to 315 deg)")))
    for key, wanted in WANTED.items():
        ratio = next(r for r in rows if (r["method"], r["protocol"]) == key
                     and r["row"] == "Gross Window-Wall Ratio [%]")
        for b in BINS:
            expected = None if wanted[b] is None else pytest.approx(100 * wanted[b], abs=1e-4)
            assert _num(ratio[columns[b]]) == expected
    truth = [r for r in rows if r["method"] == "truth"]
    gross = next(r for r in truth if r["row"] == "Gross Wall Area [m2]")
    assert float(gross["Total"]) == pytest.approx(288.0)
    ratio = next(r for r in truth if r["row"] == "Gross Window-Wall Ratio [%]")
    assert float(ratio["Total"]) == pytest.approx(100 * 49.8 / 288.0, abs=1e-4)


def test_cea_columns(exported):
    _, rows = _csv_rows(exported / "cea_architecture.csv")
    assert list(rows[0]) == ["name", "method", "protocol", "wwr_north", "wwr_east",
                             "wwr_south", "wwr_west"]
    got = {(r["method"], r["protocol"]): r for r in rows}
    for key, wanted in WANTED.items():
        for b in BINS:
            value = _num(got[key][f"wwr_{BIN_NAMES[b]}"])
            assert value == (None if wanted[b] is None else pytest.approx(wanted[b], abs=1e-6))
    assert got[("truth", "")]["wwr_south"] == "0.0"


def _estimates(entries):
    return {(e["method"], e["protocol"]): e for e in entries}


def test_geomeppy_honeybee_teaser(exported):
    geo = json.loads((exported / "geomeppy.json").read_text())
    honey = json.loads((exported / "honeybee.json").read_text())
    teaser = json.loads((exported / "teaser.json").read_text())
    centre = {"N": "0", "E": "90", "S": "180", "W": "270"}
    for key, wanted in WANTED.items():
        g = _estimates(geo["buildings"]["box"]["estimates"])[key]
        h = _estimates(honey["buildings"]["box"])[key]
        t = _estimates(teaser["buildings"]["box"])[key]
        for i, b in enumerate(BINS):
            if wanted[b] is None:  # no (estimated) facade faces this way
                assert centre[b] not in g["wwr_map"] and h["ratios"][i] is None
                assert f"{centre[b]}.0" not in t["window_area"]
                continue
            assert g["wwr_map"][centre[b]] == pytest.approx(wanted[b], abs=1e-6)
            assert g["set_wwr_by_orientation"][BIN_NAMES[b]] == pytest.approx(wanted[b],
                                                                                abs=1e-6)
            assert h["ratios"][i] == pytest.approx(wanted[b], abs=1e-6)
            window, outer = t["window_area"][f"{centre[b]}.0"], t["outer_area"][f"{centre[b]}.0"]
            doors = t.get("door_area", {}).get(f"{centre[b]}.0", 0.0)
            assert window / (window + outer + doors) == pytest.approx(wanted[b], abs=1e-6)
    truth_geo = _estimates(geo["buildings"]["box"]["estimates"])[("truth", "")]
    assert truth_geo["wwr_map"]["180"] == 0.0  # stays 0 (geomeppy would make it 0.2)
    truth_teaser = _estimates(teaser["buildings"]["box"])[("truth", "")]
    assert truth_teaser["door_area"]["90.0"] == pytest.approx(2.1)
    assert truth_teaser["outer_area"]["90.0"] == pytest.approx(60.9)  # net of window, door
    block = geo["buildings"]["box"]["block"]
    assert block["height"] == 9.0 and len(block["coordinates"]) == 4


def _wall_figures(doc):
    """Per bin (gross m², window m²) measured from the CityJSON polygons themselves, and the
    surfaces' parent/children links checked."""
    t = doc["transform"]
    v = np.asarray(doc["vertices"], dtype=float) * t["scale"] + t["translate"]
    geometry = doc["CityObjects"]["box"]["geometry"][0]
    surfaces = geometry["semantics"]["surfaces"]
    sums = {b: [0.0, 0.0] for b in BINS}
    for surface_index, rings in enumerate(geometry["boundaries"]):
        s = surfaces[geometry["semantics"]["values"][surface_index]]
        exterior = v[rings[0]]
        area_vec = sum(np.cross(a, b) for a, b in zip(exterior, np.roll(exterior, -1, 0))) / 2
        if s["type"] == "WallSurface":
            b = orientation_bin(math.degrees(math.atan2(area_vec[0], area_vec[1])))
            assert b == s["orientation"]
            sums[b][0] += np.linalg.norm(area_vec)
            for child in s.get("children", []):
                assert surfaces[child]["type"] == "Window"
                assert surfaces[child]["parent"] == surface_index
                assert len(rings) == 2  # the window is a hole in its wall
        else:
            parent = surfaces[s["parent"]]
            b = parent["orientation"]
            sums[b][1] += np.linalg.norm(area_vec)
            normal = area_vec / np.linalg.norm(area_vec)
            assert orientation_bin(math.degrees(math.atan2(normal[0], normal[1]))) == b
    return sums


@pytest.mark.parametrize("name, key", [("box__truth", ("truth", "")),
                                       ("box__2D-SS__ideal", ("2D-SS", "ideal")),
                                       ("box__neural3d__train", ("neural3d", "train"))])
def test_cityjson_is_valid_and_its_polygons_give_the_bins(exported, name, key):
    doc = json.loads((exported / "cityjson" / f"{name}.city.json").read_text())
    assert cityjson_errors(doc) == []
    assert doc["version"] == "2.0"
    sums = _wall_figures(doc)
    for b in BINS:
        gross, window = sums[b]
        assert gross == pytest.approx(EXPECTED[b][0], rel=1e-3)  # the truth's walls
        wanted = WANTED[key][b]
        assert window / gross == pytest.approx(wanted or 0.0, abs=1e-3)  # no window: 0


def test_cityjson_checks_catch_broken_files(exported):
    doc = json.loads((exported / "cityjson" / "box__truth.city.json").read_text())
    geometry = doc["CityObjects"]["box"]["geometry"][0]
    broken = json.loads(json.dumps(doc))
    broken["CityObjects"]["box"]["geometry"][0]["boundaries"][0][0][0] = len(doc["vertices"])
    assert any("out of range" in e for e in cityjson_errors(broken))
    broken = json.loads(json.dumps(doc))
    broken["CityObjects"]["box"]["geometry"][0]["semantics"]["values"].pop()
    assert any("shape" in e for e in cityjson_errors(broken))
    broken = json.loads(json.dumps(doc))
    broken["CityObjects"]["box"]["geometry"][0]["lod"] = "4"
    assert any("schema" in e for e in cityjson_errors(broken))
    broken = json.loads(json.dumps(doc))
    broken["vertices"].append(broken["vertices"][0])
    assert {"duplicate vertices", "1 unused vertices"} <= set(cityjson_errors(broken))
    assert geometry["type"] == "MultiSurface" and geometry["lod"] == "3"


def test_cli_reads_folders_and_north_override(tmp_path, capsys):
    data, results = tmp_path / "bench", tmp_path / "bench-results"
    write_building(data / "box" / "building.json", box_truth())
    write_result(results, ideal_result())
    write_result(results, located_result())
    (results / "broken.json").write_text("{")
    assert main(["--results", str(results), "--format", "csv,cea"]) == 0
    out = tmp_path / "bench-export"  # the default next to <X>-results, data found as <X>
    assert sorted(p.name for p in out.iterdir()) == ["cea_architecture.csv", "facades.csv",
                                                     "orientations.csv"]
    assert "skipped" in capsys.readouterr().err
    # --north-deg 0: the walls' world azimuths 210, 120, 30, 300 bin S, E, N, W.
    assert main(["--results", str(results), "--data", str(data), "--out", str(tmp_path / "o"),
                 "--format", "cea", "--north-deg", "0"]) == 0
    _, rows = _csv_rows(tmp_path / "o" / "cea_architecture.csv")
    truth = next(r for r in rows if r["method"] == "truth")
    assert [float(truth[f"wwr_{n}"]) for n in ("north", "east", "south", "west")] == \
        pytest.approx([0.3, 0.0, 12 / 90, 0.2], abs=1e-6)
    header, _ = _csv_rows(tmp_path / "o" / "cea_architecture.csv")
    assert "# north of box: 0 deg (user)" in header
    assert main(["--results", str(results), "--format", "xml", "--out", str(tmp_path / "x")]) == 2
    assert "unknown format" in capsys.readouterr().err
    assert main(["--results", str(tmp_path / "none")]) == 2
    assert "run `python -m metrics.compare` first" in capsys.readouterr().err


def test_writing_cityjson_leaves_json_floats_whole(exported):
    """cjio patches :mod:`json` when imported; the export puts it back, so files written
    afterwards in the same process (results, transforms.json) keep every digit."""
    assert json.dumps(0.1 + 0.2) == "0.30000000000000004"
    assert json.dumps({"x": 1 / 3}) == '{"x": 0.3333333333333333}'
