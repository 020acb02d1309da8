"""Presets: recipes, determinism to the byte, the tiny preset's checks, the paper's ranges."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from building_checks import check_building, check_closed_bodies, check_no_coplanar_overlap
from hypothesis import given, settings
from hypothesis import strategies as st
from paths import REPO_ROOT

from dataset.families import l_shaped, realistic, skyscraper
from dataset.families.realistic_params import REALISTIC_MODELS
from dataset.presets import (
    PRESETS,
    BuildingRecipe,
    build_building,
    main,
    preset_ranges,
    preset_recipes,
)
from envelope.mesh import LabelledMesh, write_labelled_ply
from envelope.truth import Building, write_building

ROOT = REPO_ROOT
RANGES = {
    "skyscraper": (skyscraper.FLOORS_RANGE, skyscraper.FOOTPRINT_RANGE_M2,
                   skyscraper.HEIGHT_RANGE_M, skyscraper.WWR_RANGE),
    "l_shaped": (l_shaped.FLOORS_RANGE, l_shaped.FOOTPRINT_RANGE_M2, l_shaped.HEIGHT_RANGE_M,
                 l_shaped.WWR_RANGE),
    "realistic": (realistic.FLOORS_RANGE, realistic.FOOTPRINT_RANGE_M2,
                  realistic.HEIGHT_RANGE_M, realistic.WWR_RANGE),
}


def _write(building: Building, folder: Path) -> tuple[bytes, bytes]:
    write_labelled_ply(folder / "mesh.ply", building.mesh)
    write_building(folder / "building.json", building.truth)
    return (folder / "mesh.ply").read_bytes(), (folder / "building.json").read_bytes()


@pytest.fixture(scope="module")
def tiny_buildings() -> list[Building]:
    return [build_building(r) for r in preset_recipes("tiny")]


@pytest.fixture(scope="module")
def paper_buildings() -> list[Building]:
    return [build_building(r) for r in preset_recipes("paper")]


@pytest.fixture(scope="module")
def paper_truths(paper_buildings):
    return [b.truth for b in paper_buildings]


def test_tiny_preset_is_one_small_building_per_family(tiny_buildings):
    families = [r.family for r in preset_recipes("tiny")]
    assert families == ["skyscraper", "l_shaped", "realistic"]
    sky, ell, house = (b.truth for b in tiny_buildings)
    assert sky.floors == 9 and sky.footprint_area_m2 < 35
    assert ell.floors == 4 and ell.footprint_area_m2 < 150
    assert house.name == "house"
    assert sum(len(b.mesh.faces) for b in tiny_buildings) < 5000


def test_tiny_buildings_agree_with_their_meshes(tiny_buildings):
    for building in tiny_buildings:
        check_building(building)


def test_same_recipe_gives_identical_files(tiny_buildings, tmp_path):
    for recipe, first in zip(preset_recipes("tiny"), tiny_buildings):
        a = _write(first, tmp_path / "a" / recipe.id)
        b = _write(build_building(recipe), tmp_path / "b" / recipe.id)
        assert a == b, recipe.id


@pytest.mark.slow
def test_files_are_identical_across_processes(tiny_buildings, tmp_path):
    # Another interpreter (fresh hash seeds, fresh import order) writes the same bytes.
    code = (
        "import sys; from pathlib import Path; from dataset.presets import *; "
        "from envelope.mesh import write_labelled_ply; "
        "from envelope.truth import write_building; "
        "b = build_building(preset_recipes('tiny')[0]); o = Path(sys.argv[1]); "
        "write_labelled_ply(o / 'mesh.ply', b.mesh); write_building(o / 'building.json', b.truth)"
    )
    subprocess.run([sys.executable, "-c", code, str(tmp_path / "other")], cwd=ROOT, check=True)
    mine = _write(tiny_buildings[0], tmp_path / "mine")
    other = ((tmp_path / "other" / "mesh.ply").read_bytes(),
             (tmp_path / "other" / "building.json").read_bytes())
    assert mine == other


@pytest.mark.slow
def test_paper_preset_has_28_buildings_in_the_family_ranges(paper_truths):
    recipes = preset_recipes("paper")
    assert len({r.id for r in recipes}) == 28
    assert [r.family for r in recipes].count("skyscraper") == 12
    assert [r.family for r in recipes].count("l_shaped") == 12
    assert sorted(r.model for r in recipes if r.family == "realistic") == sorted(
        REALISTIC_MODELS)
    for truth in paper_truths:
        floors, area, height, wwr = RANGES[truth.type]
        assert floors[0] <= truth.floors <= floors[1], truth.id
        assert area[0] <= truth.footprint_area_m2 <= area[1], truth.id
        assert height[0] <= truth.height_m <= height[1], truth.id
        assert wwr[0] <= truth.wwr <= wwr[1], truth.id


@pytest.mark.slow
def test_paper_buildings_agree_with_their_meshes(paper_buildings):
    for building in paper_buildings:
        check_building(building)


@pytest.mark.slow
@settings(max_examples=5, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), model=st.sampled_from(REALISTIC_MODELS))
def test_any_seed_gives_a_building_that_agrees_with_its_mesh(seed, model):
    # 450 seeds per family passed offline; here a few random ones each run.
    for family in ("skyscraper", "l_shaped", "realistic"):
        recipe = BuildingRecipe("any", family, seed, model if family == "realistic" else None)
        check_building(build_building(recipe))


def test_paper_preset_spans_its_ranges(paper_truths):
    # Each family covers at least half of each range it can reach (not one corner of it).
    ranges = preset_ranges(paper_truths)
    for family in ("skyscraper", "l_shaped"):
        floors, area, height, wwr = RANGES[family]
        got = ranges[family]
        for (lo, hi), key in ((area, "footprint_m2"), (wwr, "wwr")):
            assert got[key][1] - got[key][0] >= 0.5 * (hi - lo), (family, key, got[key])
        assert got["floors"][1] - got["floors"][0] >= 2


def test_checks_catch_broken_meshes(tiny_buildings):
    # The shared checks must fail on a mesh with a missing face and on doubled faces.
    b = tiny_buildings[0]
    m = b.mesh
    holed = LabelledMesh(m.vertices_m, m.faces[1:], m.face_label[1:], m.face_facade[1:])
    with pytest.raises(AssertionError):
        check_closed_bodies(Building(holed, b.truth))
    doubled = LabelledMesh(m.vertices_m, np.concatenate([m.faces, m.faces[:1, ::-1]]),
                           np.concatenate([m.face_label, m.face_label[:1]]),
                           np.concatenate([m.face_facade, m.face_facade[:1]]))
    with pytest.raises(AssertionError):
        check_no_coplanar_overlap(Building(doubled, b.truth))


def test_bad_recipes_and_presets_raise_helpful_errors():
    assert {"paper", "tiny", "heldout", "lod3", "segtrain"} <= set(PRESETS)
    with pytest.raises(ValueError, match="unknown preset"):
        preset_recipes("huge")
    with pytest.raises(ValueError, match="file-system safe"):
        BuildingRecipe("a/b", "skyscraper", 1)
    with pytest.raises(ValueError, match="unknown family"):
        BuildingRecipe("a", "castle", 1)
    with pytest.raises(ValueError, match="needs model"):
        BuildingRecipe("a", "realistic", 1)
    with pytest.raises(ValueError, match="only realistic"):
        BuildingRecipe("a", "skyscraper", 1, "house")
    with pytest.raises(ValueError, match="non-negative integer"):
        BuildingRecipe("a", "skyscraper", -1)
    with pytest.raises(ValueError, match="non-negative integer"):
        BuildingRecipe("a", "skyscraper", 1.5)
    assert type(BuildingRecipe("a", "skyscraper", np.int64(3)).seed) is int
    with pytest.raises(ValueError, match="needs a BuildingRecipe"):
        build_building("skyscraper_00")


def test_cli_prints_ranges_and_rejects_unknown_presets(capsys):
    assert main(["--preset", "tiny"]) == 0
    out = capsys.readouterr().out
    assert "skyscraper" in out and "l_shaped" in out and "WWR" in out
    assert main(["--preset", "huge"]) == 2
    assert "unknown preset" in capsys.readouterr().err
