"""The heldout preset: seeds the paper preset never drew from, every held-out design once."""

from dataset.families.heldout_params import HELDOUT_MODELS
from dataset.presets import build_building, preset_recipes

PAPER_CANDIDATE_SEEDS = {"skyscraper": range(1000, 1200), "l_shaped": range(2000, 2200)}


def test_heldout_recipes_are_new_seeds_and_new_designs():
    recipes = preset_recipes("heldout")
    paper = preset_recipes("paper") + preset_recipes("tiny")
    assert len({r.id for r in recipes}) == len(recipes) == 20
    assert not {r.id for r in recipes} & {r.id for r in paper}
    used = {(r.family, r.seed) for r in paper}
    for r in recipes:
        assert (r.family, r.seed) not in used
        if r.family in PAPER_CANDIDATE_SEEDS:
            assert r.seed not in PAPER_CANDIDATE_SEEDS[r.family]
    assert [r.model for r in recipes if r.family == "realistic"] == list(HELDOUT_MODELS)
    assert sum(r.family == "skyscraper" for r in recipes) == 6
    assert sum(r.family == "l_shaped" for r in recipes) == 6


def test_every_heldout_design_builds_with_its_visible_truth():
    for recipe in preset_recipes("heldout"):
        if recipe.family != "realistic":
            continue
        t = build_building(recipe).truth
        assert t.type == "realistic" and t.name == recipe.model and t.seed == recipe.seed
        v = t.visible_areas_m2()
        window, wall = v.window_m2, v.wall_m2
        assert 0 < window <= t.window_area_m2 and 0 < wall <= t.wall_area_m2
