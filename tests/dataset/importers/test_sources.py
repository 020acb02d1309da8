"""dataset.importers.source and dataset.sources: one list of sources, each detected and read
through the same two calls; generate and the importer take every source from that list."""

from __future__ import annotations

import contextlib
import io
from dataclasses import replace
from functools import partial
from pathlib import Path

import pytest
from conftest import make_box_building
from paths import FIXTURES, REPO_ROOT

import dataset.importers.mesh.building_file as building_file
from dataset import generate, importer
from dataset.examples.ifc_houses import box_house
from dataset.importers.buildnet3d.blenderproc import BLENDERPROC_SOURCE
from dataset.importers.buildnet3d.buildnet3d import BUILDNET3D_SOURCE
from dataset.importers.citygml.source import CITYGML_SOURCE
from dataset.importers.import_config import ImportConfig
from dataset.importers.mesh.building_file import IFC_SOURCE, MESH_SOURCE, BuildingFileOptions
from dataset.importers.mesh.mesh_import import import_labelled_mesh
from dataset.importers.source import (
    BuildingEntry,
    NoOptions,
    SceneEntry,
    Source,
    pick_source,
    write_scenes,
)
from dataset.scenes.scene_writer import GenerateConfig, scene_changes
from dataset.sources import PRESET_SOURCE, SOURCES
from envelope.scenes.scene import read_scene
from envelope.truth import Building, read_building

EXAMPLE = REPO_ROOT / "dataset" / "examples" / "example_bim.ply"
SMALL = GenerateConfig(resolution=32, views=4)


def test_one_list_names_every_source_once_and_generate_offers_each():
    assert [s.name for s in SOURCES] == ["preset", "mesh", "ifc", "buildnet3d-blenderproc",
                                         "buildnet3d-blender", "citygml", "photos"]
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf), pytest.raises(SystemExit):
        generate.main(["--help"])
    for flag in {s.flag for s in SOURCES} | {"--input"}:
        assert flag in buf.getvalue()


def test_each_source_detects_its_own_paths(tmp_path):
    ifc = tmp_path / "house.ifc"
    box_house(ifc)
    official = tmp_path / "bp"
    for sub in ("images", "semantic"):
        (official / sub).mkdir(parents=True)
    (official / "meta_data.json").write_text("{}")
    blender = tmp_path / "blender" / "images" / "building3"
    blender.mkdir(parents=True)
    (blender / "meta_data.json").write_text("{}")
    city = FIXTURES / "citygml"
    cases = {"tiny": PRESET_SOURCE, str(EXAMPLE): MESH_SOURCE, str(ifc): IFC_SOURCE,
             str(official): BLENDERPROC_SOURCE, str(tmp_path / "blender"): BUILDNET3D_SOURCE,
             str(blender): BUILDNET3D_SOURCE, str(city / "4018259.xml.xz"): CITYGML_SOURCE,
             str(city): CITYGML_SOURCE}
    for path, source in cases.items():
        assert [s for s in SOURCES if s.detect(path)] == [source], path
    with pytest.raises(ValueError, match="holds nothing these sources read: .*--mesh"):
        pick_source(SOURCES, tmp_path / "notes.txt")


def test_a_building_file_is_read_without_importing_and_records_its_inputs():
    (entry,) = MESH_SOURCE.read(EXAMPLE, BuildingFileOptions(ImportConfig(ground_z_m=0.1)))
    assert entry.name == "example_bim" and entry.seed is None
    assert set(entry.inputs) == {"source", "import"} and entry.inputs["import"]["ground_z_m"] == 0.1
    built = entry.build()
    assert built.truth.id == "example_bim"
    assert built.truth.wwr == import_labelled_mesh(
        EXAMPLE, config=ImportConfig(ground_z_m=0.1)).truth.wwr
    named = MESH_SOURCE.read(EXAMPLE, BuildingFileOptions(building_id="mine"))[0]
    assert named.name == "mine" and named.build().truth.id == "mine"
    with pytest.raises(ValueError, match="apply to IFC models only"):
        MESH_SOURCE.read(EXAMPLE, BuildingFileOptions(ifc_classes=EXAMPLE))
    with pytest.raises(ValueError, match="missing.ifc does not exist"):
        IFC_SOURCE.read(EXAMPLE.parent / "missing.ifc", BuildingFileOptions())


def test_input_picks_the_source_and_a_rerun_neither_imports_nor_renders(tmp_path, monkeypatch):
    out = tmp_path / "out"
    argv = ["--input", str(EXAMPLE), "--out", str(out), "--resolution", "32", "--views", "4",
            "--quiet"]
    with contextlib.redirect_stdout(io.StringIO()):
        assert generate.main(argv) == 0
    scene = out / "example_bim"  # its record: the file's fingerprint and the import options
    assert scene_changes(scene, SMALL, 0, building_file.file_inputs(
        EXAMPLE, BuildingFileOptions())) == []
    stamp = (scene / "transforms.json").stat().st_mtime_ns

    def no_import(*args, **kwargs):
        raise AssertionError("a finished scene was imported again")

    monkeypatch.setattr(building_file, "_import_mesh", no_import)
    with contextlib.redirect_stdout(io.StringIO()):
        assert generate.main(argv) == 0
        assert generate.main(["--mesh", str(EXAMPLE), *argv[2:]]) == 0
    assert (scene / "transforms.json").stat().st_mtime_ns == stamp


def _two_boxes(path: str | Path, options: NoOptions) -> tuple[BuildingEntry, ...]:
    """A stand-in for a file of several buildings (as CityGML holds them)."""
    return tuple(BuildingEntry(name, partial(_box, name), {"file": str(path), "building": name})
                 for name in ("north", "south"))


def _box(name: str) -> Building:
    box = make_box_building()
    return Building(box.mesh, replace(box.truth, id=name))


def test_a_source_of_many_buildings_renders_each_and_resumes(tmp_path):
    many = Source(name="boxes", flag="--boxes", help="two boxes",
                  detect=lambda path: str(path).endswith(".boxes"), read=_two_boxes)
    assert pick_source([*SOURCES, many], "city.boxes") is many
    entries = many.read("city.boxes", NoOptions())
    scenes = generate.generate_entries(entries, tmp_path, SMALL, progress=False)
    assert [s.name for s in scenes] == ["north", "south"]
    for scene, entry in zip(scenes, entries):
        assert read_scene(scene).building.id == entry.name
        assert scene_changes(scene, SMALL, 0, dict(entry.inputs)) == []
    stamp = (scenes[0] / "transforms.json").stat().st_mtime_ns
    generate.generate_entries(entries, tmp_path, SMALL, progress=False)
    assert (scenes[0] / "transforms.json").stat().st_mtime_ns == stamp


def _write_marker(folder: Path, text: str) -> None:
    (folder / "marker.txt").write_text(text)


def test_scene_entries_are_written_atomically_and_kept(tmp_path):
    first = [SceneEntry("a", partial(_write_marker, text="one"))]
    assert write_scenes(first, tmp_path, progress=False) == [tmp_path / "a"]
    write_scenes([SceneEntry("a", partial(_write_marker, text="two"))], tmp_path,
                 progress=False)
    assert (tmp_path / "a" / "marker.txt").read_text() == "one"  # kept unless overwrite

    def broken(folder: Path) -> None:
        (folder / "half.txt").write_text("half")
        raise ValueError("broken layout")

    with pytest.raises(ValueError, match="broken layout"):
        write_scenes([SceneEntry("b", broken)], tmp_path, progress=False)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a"]


def test_the_importer_is_an_alias_of_the_same_sources(tmp_path, capsys):
    assert importer.main([str(EXAMPLE), str(tmp_path / "mesh"), "--id", "bim"]) == 0
    truth = read_building(tmp_path / "mesh" / "building.json")
    assert truth.id == "bim" and truth.wwr == import_labelled_mesh(EXAMPLE).truth.wwr
    ifc = tmp_path / "box.ifc"
    box_house(ifc)
    assert importer.main([str(ifc), str(tmp_path / "ifc")]) == 0
    assert read_building(tmp_path / "ifc" / "building.json").id == "box"
    assert importer.main([str(tmp_path / "absent.ply"), str(tmp_path / "x")]) == 2
    assert "absent.ply does not exist" in capsys.readouterr().err
