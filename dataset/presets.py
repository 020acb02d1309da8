"""Named sets of buildings (presets) and the one entry point that builds a building from a recipe.

A :class:`BuildingRecipe` names a family, a seed and, for the realistic family,
a model; :func:`build_building` turns it into mesh + truth deterministically
(``numpy.random.default_rng(seed)`` drives the family's sampler). Presets:

- ``paper``: 12 skyscrapers, 12 L-shaped buildings and the four realistic models;
- ``tiny``: one small building per family (a 9-storey skyscraper, a 4-storey L-shape
  and the realistic house), cheap to render, for tests and defaults;
- ``heldout``: buildings nothing is tuned on (``docs/metrics.md``): six skyscrapers and
  six L-shaped buildings at seeds outside the ``paper`` preset's, and the eight held-out
  designs of :mod:`dataset.families.heldout` (family realistic);
- ``lod3``: 49 real buildings, the Ingolstadt LoD3 CityGML models that have windows
  (family ``citygml``; files in ``dataset/examples/lod3_ingolstadt``, CC BY-SA 4.0,
  :mod:`dataset.importers.citygml.preset`).
- ``segtrain``: 24 skyscrapers and 24 L-shaped buildings that are never evaluated, the
  training set of the mask segmenter (``segment/``); no realistic building (its four
  designs, only jittered, are the evaluated ones).
- ``approval``: the place to ask "does this change do harm?" without touching ``heldout``:
  six skyscrapers and six L-shaped buildings, and the eight held-out designs, at seeds no
  other preset uses.

What each preset may be used for (tuning, approval, report only): :mod:`dataset.set_roles`.

Run ``python -m dataset.presets`` to print the ranges a preset spans.
"""

from __future__ import annotations

import argparse
import re
from dataclasses import dataclass
from typing import Literal

import numpy as np
from tqdm import tqdm

from dataset.families.heldout import make_heldout, sample_heldout_params
from dataset.families.heldout_params import HELDOUT_MODELS
from dataset.families.l_shaped import make_l_shaped, sample_l_shaped_params
from dataset.families.realistic import make_realistic, sample_realistic_params
from dataset.families.realistic_params import REALISTIC_MODELS
from dataset.families.skyscraper import make_skyscraper, sample_skyscraper_params
from envelope.cli_errors import add_debug_flag, run_cli
from envelope.truth import Building, BuildingTruth

Family = Literal["skyscraper", "l_shaped", "realistic", "citygml"]
FAMILIES: tuple[str, ...] = ("skyscraper", "l_shaped", "realistic", "citygml")
PRESETS = ("paper", "tiny", "heldout", "lod3", "segtrain", "approval")
_SAFE_ID = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")

# Seeds of the tiny preset, picked because their samples are small (9 and 4 storeys, small
# footprints); tests/dataset/test_presets.py checks that they stay small.
_TINY_SKYSCRAPER_SEED = 38
_TINY_L_SHAPED_SEED = 37
# Seeds of the paper preset: from seeds 1000-1199 (2000-2199), those whose samples reach the
# lowest and highest floors, footprint, height and WWR, filled up with the first others, so
# that 12 buildings span each family's ranges (docs/buildings.md lists the ranges reached).
_PAPER_SEEDS = {
    "skyscraper": (1000, 1001, 1002, 1003, 1012, 1023, 1044, 1098, 1122, 1130, 1174, 1191),
    "l_shaped": (2000, 2001, 2002, 2003, 2004, 2005, 2006, 2040, 2046, 2060, 2122, 2143),
}
_REALISTIC_SEED = 3000
# Seeds of the heldout preset: the first six from 5000 (6000) with no picking, outside the
# paper preset's candidates (1000-1199, 2000-2199) and the tiny preset's; the held-out designs
# from 7000.
_HELDOUT_SEEDS = {"skyscraper": tuple(range(5000, 5006)), "l_shaped": tuple(range(6000, 6006))}
_HELDOUT_DESIGN_SEED = 7000
_LOD3_SEED = 4000  # + the building's index: cameras and looks of the lod3 scenes
# Seeds of the segtrain preset: far from every evaluated preset's seeds (paper 1000-2199 and
# 3000-3003, tiny, heldout 5000-7007, lod3 4000-4048), so the segmenter never sees a building
# that is measured.
_SEGTRAIN_FIRST_SEED = {"skyscraper": 1_000_000, "l_shaped": 2_000_000}
_SEGTRAIN_PER_FAMILY = 24
# Seeds of the approval preset: the first six from 8000 (9000), the held-out designs from 9500;
# outside every other preset's seeds.
_APPROVAL_SEEDS = {"skyscraper": tuple(range(8000, 8006)), "l_shaped": tuple(range(9000, 9006))}
_APPROVAL_DESIGN_SEED = 9500


@dataclass(frozen=True)
class BuildingRecipe:
    """How to build one building: ``id`` (file-system safe), family, seed, and ``model``: the
    realistic model (one of the realistic family's models or of the held-out designs), or a
    ``citygml`` building's file in the lod3 data folder."""

    id: str
    family: Family
    seed: int
    model: str | None = None

    def __post_init__(self) -> None:
        if not _SAFE_ID.match(self.id):
            raise ValueError(
                f"building id {self.id!r} is not file-system safe; "
                "use letters, digits, '_', '-' and '.'"
            )
        if self.family not in FAMILIES:
            raise ValueError(f"unknown family {self.family!r}; choose one of {', '.join(FAMILIES)}")
        if self.family == "realistic" and self.model not in (*REALISTIC_MODELS,
                                                             *HELDOUT_MODELS):
            raise ValueError(
                f"a realistic recipe needs model one of "
                f"{', '.join((*REALISTIC_MODELS, *HELDOUT_MODELS))}, got {self.model!r}"
            )
        if self.family == "citygml" and not self.model:
            raise ValueError("a citygml recipe needs model = its file in the lod3 data folder")
        if self.family not in ("realistic", "citygml") and self.model is not None:
            raise ValueError(f"only realistic and citygml recipes take a model, got "
                             f"model={self.model!r}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, int | np.integer) or (
            self.seed < 0
        ):
            raise ValueError(f"seed must be a non-negative integer, got {self.seed!r}")
        object.__setattr__(self, "seed", int(self.seed))  # numpy ints do not go into JSON


def preset_recipes(name: str) -> tuple[BuildingRecipe, ...]:
    """The recipes of preset ``name`` (one of :data:`PRESETS`)."""
    if name == "tiny":
        return (
            BuildingRecipe("tiny_skyscraper", "skyscraper", _TINY_SKYSCRAPER_SEED),
            BuildingRecipe("tiny_l_shaped", "l_shaped", _TINY_L_SHAPED_SEED),
            BuildingRecipe("realistic_house", "realistic", _REALISTIC_SEED, "house"),
        )
    if name == "paper":
        recipes = [
            BuildingRecipe(f"{family}_{i:02d}", family, seed)
            for family in ("skyscraper", "l_shaped")
            for i, seed in enumerate(_PAPER_SEEDS[family])
        ]
        recipes += [
            BuildingRecipe(f"realistic_{m}", "realistic", _REALISTIC_SEED + k, m)
            for k, m in enumerate(REALISTIC_MODELS)
        ]
        return tuple(recipes)
    if name in ("heldout", "approval"):
        seeds, design_seed = ((_HELDOUT_SEEDS, _HELDOUT_DESIGN_SEED) if name == "heldout"
                              else (_APPROVAL_SEEDS, _APPROVAL_DESIGN_SEED))
        recipes = [
            BuildingRecipe(f"{name}_{family}_{i:02d}", family, seed)
            for family in ("skyscraper", "l_shaped")
            for i, seed in enumerate(seeds[family])
        ]
        recipes += [
            BuildingRecipe(f"{name}_{m}", "realistic", design_seed + k, m)
            for k, m in enumerate(HELDOUT_MODELS)
        ]
        return tuple(recipes)
    if name == "lod3":
        from dataset.importers.citygml.preset import lod3_entries

        return tuple(BuildingRecipe(e.id, "citygml", _LOD3_SEED + k, e.file)
                     for k, e in enumerate(lod3_entries()))
    if name == "segtrain":
        return tuple(
            BuildingRecipe(f"segtrain_{family}_{i:02d}", family, first + i)
            for family, first in _SEGTRAIN_FIRST_SEED.items()
            for i in range(_SEGTRAIN_PER_FAMILY)
        )
    raise ValueError(f"unknown preset {name!r}; choose one of {', '.join(PRESETS)}")


def build_building(recipe: BuildingRecipe) -> Building:
    """Mesh and exact truth of ``recipe`` (same recipe -> identical mesh and truth)."""
    if not isinstance(recipe, BuildingRecipe):
        raise ValueError(f"build_building needs a BuildingRecipe, got {type(recipe).__name__}")
    if recipe.family == "citygml":
        from dataset.importers.citygml.preset import build_lod3_building

        return build_lod3_building(recipe.id, recipe.model)
    rng = np.random.default_rng(recipe.seed)
    if recipe.family == "skyscraper":
        params = sample_skyscraper_params(rng)
        return make_skyscraper(params, building_id=recipe.id, seed=recipe.seed)
    if recipe.family == "l_shaped":
        params = sample_l_shaped_params(rng)
        return make_l_shaped(params, building_id=recipe.id, seed=recipe.seed)
    if recipe.model in HELDOUT_MODELS:
        return make_heldout(sample_heldout_params(rng, recipe.model), building_id=recipe.id,
                            seed=recipe.seed)
    params = sample_realistic_params(rng, recipe.model)
    return make_realistic(params, building_id=recipe.id, seed=recipe.seed)


def preset_ranges(truths: list[BuildingTruth]) -> dict[str, dict[str, tuple[float, float]]]:
    """Per family: (min, max) of floors, footprint m², height m and WWR over ``truths``."""
    out: dict[str, dict[str, tuple[float, float]]] = {}
    for family in sorted({t.type for t in truths}):
        group = [t for t in truths if t.type == family]
        out[family] = {
            key: (min(getattr(t, attr) for t in group), max(getattr(t, attr) for t in group))
            for key, attr in (("floors", "floors"), ("footprint_m2", "footprint_area_m2"),
                              ("height_m", "height_m"), ("wwr", "wwr"))
        }
        out[family]["count"] = (len(group), len(group))
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m dataset.presets",
        description="Build every building of a preset (no rendering) and print, per family, "
        "how many there are and the range of floors, footprint area, height and WWR.",
    )
    parser.add_argument("--preset", default="paper", help=f"one of {', '.join(PRESETS)}")
    add_debug_flag(parser)
    args = parser.parse_args(argv)

    def body() -> int:
        recipes = preset_recipes(args.preset)
        truths = [build_building(r).truth
                  for r in tqdm(recipes, desc="building", unit="building")]
        print(f"preset {args.preset}: {len(truths)} buildings")
        for family, ranges in preset_ranges(truths).items():
            f, a, h, w = (ranges[k] for k in ("floors", "footprint_m2", "height_m", "wwr"))
            print(
                f"  {family:<10} n={ranges['count'][0]:>2}  floors {f[0]}-{f[1]}  "
                f"footprint {a[0]:.1f}-{a[1]:.1f} m2  height {h[0]:.1f}-{h[1]:.1f} m  "
                f"WWR {w[0]:.3f}-{w[1]:.3f}"
            )
        return 0

    return run_cli("dataset.presets", body, debug=args.debug)


if __name__ == "__main__":
    raise SystemExit(main())
