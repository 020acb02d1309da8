"""Cache keys name what a result depends on: a stored method result and a neural3d training
stay valid when an importer, a building family or a bench script is edited, and go stale when
a method or the core (``envelope``) is edited.

The keys are the ones the runner and the training compare with what is stored
(:func:`metrics.run.runner.expected_provenance`, :func:`neural3d.training.run_folder.
training_provenance`), computed in a fresh interpreter on a copy of the code with one file
edited. Only their ``code`` part can change with an edit; the stored record matches when
:func:`envelope.provenance.provenance_changes` finds nothing.
"""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from paths import REPO_ROOT

PACKAGES = ("envelope", "dataset", "baselines", "neural3d", "metrics", "segment", "bench")
KEYS = """
import json, sys
from pathlib import Path
import torch
from metrics.run.methods import method_specs
from metrics.run.runner import expected_provenance
from neural3d.config import TrainConfig
from neural3d.training.run_folder import training_provenance
scene = Path(sys.argv[1])
specs = method_specs(("2D-S", "2D-SS", "neural3d"), ("ideal",), scene / "results")
keys = {s.name: expected_provenance(scene, s).code for s in specs}
keys["training"] = training_provenance(scene, TrainConfig(), torch.device("cpu")).code
print(json.dumps(keys))
"""


def _copy_of_the_code(root: Path) -> Path:
    for package in PACKAGES:
        shutil.copytree(REPO_ROOT / package, root / package,
                        ignore=shutil.ignore_patterns("__pycache__", "*.pt", "*.xz", "*.ply",
                                                      "examples"))
    return root


def _keys(code: Path, scene: Path) -> dict[str, dict[str, str]]:
    env = {**os.environ, "PYTHONPATH": str(code), "OMP_NUM_THREADS": "1"}
    out = subprocess.run([sys.executable, "-c", KEYS, str(scene)], cwd=code, env=env,
                         capture_output=True, text=True, timeout=300, check=True)
    return json.loads(out.stdout)


def _edit(path: Path) -> None:
    path.write_text(path.read_text() + "\n# an edit\n")


@pytest.fixture(scope="module")
def before(tmp_path_factory):
    code = _copy_of_the_code(tmp_path_factory.mktemp("code"))
    scene = tmp_path_factory.mktemp("scene")
    (scene / "transforms.json").write_text("{}")
    return code, scene, _keys(code, scene)


@pytest.mark.slow
@pytest.mark.parametrize("edited", [
    "dataset/importers/citygml/read.py",
    "dataset/importers/ifc/convert.py",
    "dataset/families/skyscraper.py",
    "dataset/generate.py",
    "bench/baselines.py",
])
def test_an_edit_outside_the_methods_and_the_core_keeps_every_key(before, edited):
    code, scene, keys = before
    original = (code / edited).read_text()
    try:
        _edit(code / edited)
        assert _keys(code, scene) == keys
    finally:
        (code / edited).write_text(original)


@pytest.mark.slow
@pytest.mark.parametrize(("edited", "stale"), [
    ("baselines/wwr2ds.py", {"2D-S", "2D-SS"}),
    ("neural3d/extraction/measure.py", {"neural3d"}),
    ("neural3d/field/fields.py", {"neural3d", "training"}),
    ("envelope/wwr.py", {"2D-S", "2D-SS", "neural3d", "training"}),
    ("envelope/scenes/scene.py", {"2D-S", "2D-SS", "neural3d", "training"}),
])
def test_an_edit_to_a_method_or_the_core_makes_its_keys_stale(before, edited, stale):
    code, scene, keys = before
    original = (code / edited).read_text()
    try:
        _edit(code / edited)
        after = _keys(code, scene)
    finally:
        (code / edited).write_text(original)
    assert {name for name in keys if after[name] != keys[name]} == stale


def test_the_copy_holds_the_edited_files():
    for edited in ("dataset/importers/citygml/read.py", "dataset/families/skyscraper.py",
                   "baselines/wwr2ds.py", "neural3d/extraction/measure.py",
                   "neural3d/field/fields.py", "envelope/scenes/scene.py"):
        assert (REPO_ROOT / edited).is_file(), edited
