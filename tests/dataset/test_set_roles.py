"""dataset.set_roles: every preset has a role, the approval preset's seeds are its own, and a
settings bench refuses report-only scenes."""

import json
import subprocess
import sys

import pytest
from paths import REPO_ROOT

from dataset.presets import PRESETS, preset_recipes
from dataset.set_roles import PRESET_ROLES, refuse_report_only, report_only_presets, scene_preset


def _scene(root, name, preset):
    folder = root / name
    folder.mkdir()
    inputs = {"seed": 1} if preset is None else {"preset": preset, "recipe": name, "seed": 1}
    (folder / "transforms.json").write_text(json.dumps(
        {"generator": {"provenance": {"inputs": inputs}}, "frames": []}))
    return folder


def test_every_preset_has_a_role():
    assert set(PRESET_ROLES) == set(PRESETS)
    assert {p for p, r in PRESET_ROLES.items() if r == "report"} == {"heldout", "lod3"}
    assert PRESET_ROLES["approval"] == "approval"


def test_the_approval_preset_uses_seeds_no_other_preset_uses():
    approval = preset_recipes("approval")
    assert len(approval) == 20 and len({r.id for r in approval}) == 20
    others = {(r.family, r.seed) for p in PRESETS if p not in ("approval", "lod3")
              for r in preset_recipes(p)}
    assert not others & {(r.family, r.seed) for r in approval}
    heldout_designs = {r.model for r in preset_recipes("heldout") if r.model}
    assert {r.model for r in approval if r.model} == heldout_designs


def test_report_only_scenes_are_refused_and_others_pass(tmp_path):
    scenes = [_scene(tmp_path, "a", "paper"), _scene(tmp_path, "b", "approval"),
              _scene(tmp_path, "mine", None), tmp_path / "empty"]
    assert [scene_preset(s) for s in scenes] == ["paper", "approval", None, None]
    refuse_report_only(scenes, "choose a setting")  # nothing report-only: no error
    held = [_scene(tmp_path, n, "heldout") for n in ("h1", "h2", "h3", "h4")]
    assert report_only_presets(scenes + held) == {"heldout": ["h1", "h2", "h3", "h4"]}
    with pytest.raises(ValueError, match=r"refusing to choose a setting on report-only scenes "
                                         r"\(heldout: h1, h2, h3 \.\.\.\)"):
        refuse_report_only(scenes + held, "choose a setting")


@pytest.mark.slow
def test_a_settings_bench_refuses_a_report_only_benchmark(tmp_path):
    _scene(tmp_path, "l1", "lod3")
    out = subprocess.run([sys.executable, "bench/dss_outline_area.py", "--data", str(tmp_path)],
                         cwd=REPO_ROOT, capture_output=True, text=True, timeout=120)
    assert out.returncode == 2 and "report-only scenes (lod3: l1)" in out.stderr
