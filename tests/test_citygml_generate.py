"""CityGML into scenes: ``python -m dataset.generate --citygml`` and the ``lod3`` preset."""

from __future__ import annotations

import json
from pathlib import Path

from dataset.core.truth import read_building
from dataset.generate import main
from dataset.importers.citygml_import import import_citygml
from dataset.importers.citygml_preset import LOD3_DIR, lod3_entries
from dataset.presets import build_building, preset_recipes

FIXTURES = Path(__file__).parent / "fixtures" / "citygml"
TINY = ["--resolution", "48", "--views", "2", "--quiet"]


def test_generate_citygml_writes_one_scene_per_building(tmp_path):
    out = tmp_path / "scenes"
    assert main(["--citygml", str(FIXTURES / "4018259.xml.xz"), "--out", str(out), *TINY]) == 0
    scene = out / "4018259"
    truth = read_building(scene / "building.json")
    assert truth == import_citygml(FIXTURES / "4018259.xml.xz")[0].truth
    frames = json.loads((scene / "transforms.json").read_text())["frames"]
    ideal = {f["facade_id"] for f in frames if f["split"] == "ideal"}
    assert ideal <= {f.id for f in truth.facades} and ideal
    # A rerun finds the scene finished and leaves it alone.
    before = (scene / "transforms.json").stat().st_mtime_ns
    assert main(["--citygml", str(FIXTURES / "4018259.xml.xz"), "--out", str(out), *TINY]) == 0
    assert (scene / "transforms.json").stat().st_mtime_ns == before


def test_bad_citygml_leaves_nothing_written(tmp_path, capsys):
    """One truncated file among good ones: exit 2, the error names it, no scene is written."""
    src = tmp_path / "city"
    src.mkdir()
    (src / "a.gml.xz").write_bytes((FIXTURES / "4018133.xml.xz").read_bytes())
    (src / "b.gml.xz").write_bytes((FIXTURES / "4018259.xml.xz").read_bytes()[:2000])
    out = tmp_path / "scenes"
    assert main(["--citygml", str(src), "--out", str(out), *TINY]) == 2
    err = capsys.readouterr().err
    assert "b.gml.xz is not well-formed XML" in err
    assert not out.exists() or not any(out.iterdir())


def test_lod3_preset_lists_the_shipped_buildings():
    entries = lod3_entries()
    assert len(entries) == 49 and len({e.id for e in entries}) == 49
    shipped = sorted(p.name for p in LOD3_DIR.glob("*.xml.xz"))
    assert sorted({e.file for e in entries}) == shipped
    assert (LOD3_DIR / "LICENSE").read_text().startswith("Attribution-ShareAlike 4.0")
    recipes = preset_recipes("lod3")
    assert [r.id for r in recipes] == [e.id for e in entries]
    assert all(r.family == "citygml" for r in recipes)


def test_lod3_recipe_builds_the_same_building_as_the_fixture():
    (recipe,) = [r for r in preset_recipes("lod3") if r.id == "4018259"]
    assert build_building(recipe).truth == import_citygml(FIXTURES / "4018259.xml.xz")[0].truth
