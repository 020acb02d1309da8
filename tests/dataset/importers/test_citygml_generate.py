"""CityGML into scenes: ``python -m dataset.generate --citygml`` and the ``lod3`` preset."""

from __future__ import annotations

import json

import pytest
from paths import FIXTURES

from dataset.generate import main
from dataset.importers.citygml.convert import import_citygml
from dataset.importers.citygml.preset import LOD3_DIR, lod3_entries, lod3_files
from dataset.presets import build_building, preset_recipes
from envelope.truth import read_building

FIXTURES = FIXTURES / "citygml"
TINY = ["--resolution", "48", "--views", "2", "--quiet"]


@pytest.mark.slow
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
    shipped = sorted(str(p.relative_to(LOD3_DIR)) for p in LOD3_DIR.glob("*/*.xml.xz"))
    assert sorted(str(f.path.relative_to(LOD3_DIR)) for f in lod3_files()) == shipped
    assert {e.file for e in entries} < set(shipped)  # 5 files hold neighbours alone
    assert len(shipped) == 53
    assert (LOD3_DIR / "LICENSE").read_text().startswith("Attribution-ShareAlike 4.0")
    recipes = preset_recipes("lod3")
    assert [r.id for r in recipes] == [e.id for e in entries]
    assert all(r.family == "citygml" for r in recipes)


@pytest.mark.slow
def test_lod3_recipe_builds_the_same_building_as_the_fixture():
    """Same file, same facades and areas; the preset's building also has the neighbours of
    the shipped city model (the fixture imported alone has none)."""
    (recipe,) = [r for r in preset_recipes("lod3") if r.id == "4018259"]
    preset = build_building(recipe)
    alone = import_citygml(FIXTURES / "4018259.xml.xz")[0]
    assert preset.truth.facades == alone.truth.facades
    assert preset.truth.wwr == alone.truth.wwr
    assert preset.mesh.faces.tolist() == alone.mesh.faces.tolist()
    assert len(preset.context) == 6 and alone.context == ()
    # The fixture folder has no textures: its X3D colours only, its textures missing.
    assert len(preset.appearance.images) > len(alone.appearance.images)
    assert alone.truth.extra["warnings"]["texture image missing: procedural look"] > 0


@pytest.mark.slow
def test_make_lod3_copies_files_with_windows_and_writes_the_manifest(tmp_path):
    """The maker of the shipped folder, on a miniature clone: two buildings with windows, one
    file without any building window (a neighbour alone: the OGC house's 2.0 file has two,
    so an edited copy without its windows stands in), and a texture to downscale."""
    import lzma

    import numpy as np
    from PIL import Image

    from dataset.importers.citygml.preset import TEXTURE_MAX_PX
    from dataset.importers.citygml.preset import main as make_main

    src = tmp_path / "models" / "building" / "lod3" / "individual" / "citygml"
    for i in ("4018259", "4018133"):
        (src / i).mkdir(parents=True)
        (src / i / f"{i}.xml").write_bytes(lzma.decompress((FIXTURES / f"{i}.xml.xz")
                                                           .read_bytes()))
    bare = lzma.decompress((FIXTURES / "4018149b.xml.xz").read_bytes()).decode()
    start = bare.index("<bldg:opening>")
    while "<bldg:opening>" in bare:
        start = bare.index("<bldg:opening>")
        bare = bare[:start] + bare[bare.index("</bldg:opening>", start) + 15:]
    (src / "4018149b").mkdir()
    (src / "4018149b" / "4018149b.xml").write_text(bare)
    (src.parents[1] / "LICENSE").write_text("Attribution-ShareAlike 4.0 International\n")
    (src / "4018259" / "textures").mkdir()
    Image.fromarray(np.full((600, 400, 3), 90, np.uint8)).save(
        src / "4018259" / "textures" / "Metal Silver.jpg")
    out = tmp_path / "out"
    assert make_main([str(src), "--out", str(out)]) == 0
    entries = lod3_entries(out)
    assert [e.id for e in entries] == ["4018133", "4018259"]
    assert [e.file for e in entries] == ["4018133/4018133.xml.xz", "4018259/4018259.xml.xz"]
    files = lod3_files(out)
    assert sorted(str(f.path.relative_to(out)) for f in files) == [
        "4018133/4018133.xml.xz", "4018149b/4018149b.xml.xz", "4018259/4018259.xml.xz"]
    assert all(f.bbox_m[2] > f.bbox_m[0] and f.bbox_m[3] > f.bbox_m[1] for f in files)
    assert lzma.decompress((out / "4018259" / "4018259.xml.xz").read_bytes()) == (
        src / "4018259" / "4018259.xml").read_bytes()
    with Image.open(out / "4018259" / "textures" / "Metal Silver.jpg") as im:
        assert im.size == (round(TEXTURE_MAX_PX * 400 / 600), TEXTURE_MAX_PX)
    assert (out / "LICENSE").read_text().startswith("Attribution-ShareAlike")
    assert make_main([str(tmp_path / "nowhere"), "--out", str(out)]) == 2
