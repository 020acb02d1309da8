"""Methods never see the truth: every built-in method, run the way metrics runs it, gives
identical results on a scene copy whose truth is poisoned or gone (docs/DESIGN.md).

The poisoned copy has another building's ``building.json`` and ``mesh.ply``, no facade-id
(``instances/``) or normal images, and another generator record in ``transforms.json``.
neural3d runs with a 60-step budget (the fewest whose mesh has facades here), twice from
scratch, so its two trainings are compared, not one reused.
"""

from __future__ import annotations

import json
import shutil
from dataclasses import asdict, replace
from pathlib import Path

import numpy as np
import pytest
from conftest import make_box_building

from envelope.mesh import LabelledMesh, write_labelled_ply
from envelope.method_input import ALL_INPUTS, MethodInput, method_input
from envelope.protocols import DEFAULT_PROTOCOLS
from envelope.scenes.scene import read_method_input, read_scene
from envelope.truth import read_building, write_building
from metrics.run.methods import METHODS, built_in_method, spec_from_method
from metrics.run.runner import Job, run_job
from neural3d.method import Neural3dBudget

NAME = "box"  # both copies carry the same folder name: a scene's name is in its results
CHEAP = {"neural3d": Neural3dBudget(preset="tiny", steps=60, threads=1, resolution=24,
                                    eval_frames=1)}
"""Configs that keep a method cheap here; the others run with their defaults."""


def poison(scene_dir: Path) -> None:
    """Replace the truth of ``scene_dir`` by another building's, and remove what else only
    the truth could have made (facade-id and normal images, the generator's record)."""
    truth = read_building(scene_dir / "building.json")
    facades = tuple(replace(f, wwr=0.9 - f.wwr, window_area_m2=3 * f.window_area_m2,
                            normal=tuple(-x for x in f.normal)) for f in truth.facades)
    write_building(scene_dir / "building.json", replace(
        truth, wwr=0.9 - truth.wwr, facade_area_m2=2 * truth.facade_area_m2,
        height_m=3 * truth.height_m, facades=facades, facade_outlines_m={},
        footprint={"type": "Polygon", "coordinates": [[[50, 50], [60, 50], [60, 60],
                                                       [50, 60], [50, 50]]]}))
    box = make_box_building().mesh
    write_labelled_ply(scene_dir / "mesh.ply", LabelledMesh(
        box.vertices_m * 2.0 + 30.0, box.faces, np.roll(box.face_label, 7),
        np.roll(box.face_facade, 3)))
    shutil.rmtree(scene_dir / "instances")
    shutil.rmtree(scene_dir / "normals")
    tf = scene_dir / "transforms.json"
    meta = json.loads(tf.read_text())
    meta["generator"] = {"recipe": "another building", "seed": 12345}
    tf.write_text(json.dumps(meta))


@pytest.fixture(scope="module")
def copies(clean_scene, tmp_path_factory) -> tuple[Path, Path]:
    root = tmp_path_factory.mktemp("truth_blind")
    honest, blind = root / "honest" / NAME, root / "blind" / NAME
    shutil.copytree(clean_scene, honest)
    shutil.copytree(clean_scene, blind)
    poison(blind)
    return honest, blind


def test_the_copy_is_poisoned(copies):
    honest, blind = copies
    assert read_building(blind / "building.json").wwr != read_building(
        honest / "building.json").wwr
    assert not (blind / "instances").exists() and (honest / "instances").is_dir()
    with pytest.raises(ValueError, match="instances/.*does not exist"):
        read_scene(blind)  # the truth's reader would notice; the methods' never opens them


def _comparable(result) -> dict:
    record = asdict(result)
    del record["wall_time_s"], record["provenance"]
    return record


@pytest.mark.parametrize("name", [  # two neural3d trainings take ~20 s on 2 cores
    pytest.param(n, marks=pytest.mark.slow) if built_in_method(n).heavy else n for n in METHODS])
def test_every_built_in_method_gives_identical_results_without_the_truth(copies, tmp_path,
                                                                          name):
    method = built_in_method(name)
    results = []
    for scene_dir in copies:
        results_dir = tmp_path / scene_dir.parent.name  # each copy trains its own neural3d
        # the default views: the 2D methods on ideal, multi and the orbit (own facades),
        # neural3d on the orbit
        spec = spec_from_method(method, DEFAULT_PROTOCOLS, results_dir, CHEAP.get(name))
        assert spec.protocols, name
        outcomes = [run_job(Job(scene_dir, spec, p)) for p in spec.protocols]
        assert [o.status for o in outcomes] == ["ran"] * len(outcomes), [
            o.reason for o in outcomes]
        results.append([_comparable(o.result) for o in outcomes])
    honest, blind = results
    assert blind == honest
    assert all(r["wwr"] is not None for r in honest)


def test_a_method_refuses_a_scene_that_holds_the_truth(copies):
    honest, _ = copies
    scene = read_scene(honest)
    assert scene.building is not None
    for name in METHODS:
        spec = built_in_method(name)
        config = CHEAP.get(name, spec.config_type())
        with pytest.raises(TypeError, match="MethodInput"):
            spec.run(scene, spec.protocols[0], config, **(
                {"artefacts_dir": honest.parent} if spec.artefacts else {}))


def test_a_method_input_holds_only_what_is_declared(copies):
    honest, _ = copies
    scene = read_scene(honest)
    full = method_input(scene)
    assert isinstance(full, MethodInput) and full.inputs == ALL_INPUTS
    assert not hasattr(full, "building") and not hasattr(full, "extra")
    assert all(f.instance_file_path is None and f.normal_file_path is None for f in full.frames)
    assert all(f.depth_file_path and f.semantic_file_path for f in full.frames)
    masks_only = read_method_input(honest, ("semantics",))
    assert all(f.depth_file_path is None and f.semantic_file_path for f in masks_only.frames)
    assert [f.world_from_camera.tolist() for f in masks_only.frames] == [
        f.world_from_camera.tolist() for f in scene.frames]
    assert [f.facade_id for f in masks_only.frames] == [f.facade_id for f in scene.frames]
    with pytest.raises(ValueError, match="unknown method inputs"):
        method_input(scene, ("truth",))


def test_reading_a_method_input_never_opens_building_json(copies, tmp_path):
    scene = tmp_path / NAME
    shutil.copytree(copies[0], scene)
    (scene / "building.json").write_text("{not json")
    (scene / "mesh.ply").write_bytes(b"not a mesh")
    with pytest.raises(ValueError, match="not a valid building.json"):
        read_scene(scene)
    read, made = read_method_input(scene), method_input(read_scene(copies[0]))
    assert [replace(f, world_from_camera=None) for f in read.frames] == [
        replace(f, world_from_camera=None) for f in made.frames]
