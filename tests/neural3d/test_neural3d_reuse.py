"""A comparison trains a building once: a finished training with the same provenance is only
extracted again, a partial one is resumed, anything else is trained afresh."""

import ast
import json
from dataclasses import replace

import pytest
import torch
from neural3d_scene import write_ring_scene
from paths import REPO_ROOT

from envelope.scene_record import scene_name
from envelope.scenes.scene import read_method_input
from neural3d.config import config_to_dict, preset_config
from neural3d.field.checkpoint import CHECKPOINT_NAME, read_checkpoint
from neural3d.method import Neural3dBudget, run_neural3d, train_config
from neural3d.train import train
from neural3d.training.run_folder import TRAINING_CODE, prior_run, training_provenance

CPU = torch.device("cpu")
STEPS = 20
BUDGET = Neural3dBudget(preset="tiny", steps=STEPS, threads=1, resolution=24, eval_frames=1)
REPO = REPO_ROOT


@pytest.fixture(scope="module")
def scene(box_building, tmp_path_factory):
    return write_ring_scene(box_building, tmp_path_factory.mktemp("reuse") / "box", size_px=24,
                            n_train=8, n_eval=2)


def config_of(steps):
    return replace(preset_config("tiny"), iterations=steps, eval_every=10, checkpoint_every=10)


@pytest.mark.slow
def test_prior_run_tells_finished_partial_and_other(scene, tmp_path):
    torch.set_num_threads(1)
    config = config_of(STEPS)
    run = train(read_method_input(scene), config, tmp_path, device=CPU)
    expected = training_provenance(scene, config, CPU)
    assert prior_run(run, expected, STEPS) == "finished"
    assert prior_run(run, expected, STEPS + 10) == "partial"
    other = training_provenance(scene, replace(config, seed=config.seed + 1), CPU)
    assert prior_run(run, other, STEPS) == "none"
    torch.set_num_threads(2)
    assert prior_run(run, training_provenance(scene, config, CPU), STEPS) == "none"
    torch.set_num_threads(1)
    assert prior_run(tmp_path / "absent", expected, STEPS) == "none"
    record = json.loads((run / "run.json").read_text())
    del record["provenance"]  # a run folder written before the record existed
    (run / "run.json").write_text(json.dumps(record))
    assert prior_run(run, expected, STEPS) == "none"
    (run / "run.json").write_text("{damaged")
    assert prior_run(run, expected, STEPS) == "none"


@pytest.mark.slow
def test_second_run_reuses_the_training_and_measures_the_same(scene, tmp_path):
    read = read_method_input(scene)
    first = run_neural3d(read, "train", BUDGET, artefacts_dir=tmp_path)
    checkpoint = tmp_path / scene_name(scene) / CHECKPOINT_NAME
    written = checkpoint.stat().st_mtime_ns
    second = run_neural3d(read, "train", BUDGET, artefacts_dir=tmp_path)
    assert checkpoint.stat().st_mtime_ns == written  # not trained again
    assert not any("training reused" in w for w in first.warnings)
    assert any("training reused" in w for w in second.warnings)
    assert second.steps == first.steps == STEPS
    assert second.wwr == pytest.approx(first.wwr, abs=1e-12)
    assert second.facade_area_m2 == pytest.approx(first.facade_area_m2, abs=1e-9)
    state = read_checkpoint(checkpoint, CPU)
    assert second.wall_time_s >= float(state["train_s"])  # the stored training is counted


@pytest.mark.slow
def test_a_partial_run_is_resumed_to_the_budget(scene, tmp_path):
    torch.set_num_threads(BUDGET.threads)
    half = config_of(STEPS // 2)
    train(read_method_input(scene), half, tmp_path, device=CPU)
    run = tmp_path / scene_name(scene)
    # The half run's folder, relabelled as a run of the full budget stopped at step 10
    # (as Ctrl-C leaves it): same config but for the step budget.
    full = train_config(BUDGET)
    run_json = json.loads((run / "run.json").read_text())
    run_json["provenance"] = training_provenance(scene, full, CPU).to_json_dict()
    (run / "run.json").write_text(json.dumps(run_json))
    (run / "config.json").write_text(json.dumps(config_to_dict(full)))
    result = run_neural3d(read_method_input(scene), "train", BUDGET, artefacts_dir=tmp_path)
    assert result.steps == STEPS and not result.cut_short
    assert not any("training reused" in w for w in result.warnings)
    assert int(read_checkpoint(run / CHECKPOINT_NAME, CPU)["step"]) == STEPS
    # The half run evaluated at step 10 (eval_every 10), the full config only at the end
    # (eval_every 50): step 10's evaluation survives only if the run was resumed.
    evals = json.loads((run / "eval.json").read_text())["evaluations"]
    assert [e["step"] for e in evals] == [10, STEPS]


@pytest.mark.slow
def test_the_method_trains_on_the_input_it_is_given_and_writes_no_result(scene, tmp_path,
                                                                          monkeypatch):
    """neural3d reads its scene once: training takes the MethodInput it is given (here with
    every other train frame left out) and never reads the folder's transforms.json again;
    the result comes back with the config the method records, and only the runner writes
    it (the run folder keeps the mesh and the footprint)."""
    import envelope.scenes.scene as scenes
    from neural3d.method import EXTRACT_FOLDER, record_config

    read = read_method_input(scene)
    train_ids = [i for i, f in enumerate(read.frames) if f.split == "train"]
    dropped = set(train_ids[::2])
    given = replace(read, frames=tuple(f for i, f in enumerate(read.frames) if i not in dropped))

    def no_second_read(root):
        raise AssertionError(f"{root} read again")

    monkeypatch.setattr(scenes, "_read_transforms", no_second_read)
    result = run_neural3d(given, "train", BUDGET, artefacts_dir=tmp_path)
    run = tmp_path / scene_name(scene)
    assert json.loads((run / "run.json").read_text())["train_frames"] == (
        len(train_ids) - len(dropped))
    assert result.config == replace(result, config=record_config(BUDGET)).config
    assert result.steps == STEPS
    assert not [p.name for p in (run / EXTRACT_FOLDER).iterdir() if p.suffix == ".json"]
    assert (run / EXTRACT_FOLDER / "mesh.ply").is_file()


@pytest.mark.slow
def test_a_street_capture_trains_its_own_run_with_its_own_protocol(box_building, tmp_path):
    """neural3d on the ``street`` protocol trains on the street frames alone, in its own run
    folder (``<artefacts>/street/<scene>``), keyed apart from an orbit training, and its
    result names the protocol; a scene with street frames only has no orbit to train on."""
    from envelope.method import artefacts_folder
    from neural3d.field.trained import load_trained_field

    street = write_ring_scene(box_building, tmp_path / "street_box", size_px=24, n_train=8,
                              n_eval=2, split="street")
    read = read_method_input(street)
    result = run_neural3d(read, "street", BUDGET, artefacts_dir=tmp_path / "runs")
    run = artefacts_folder(tmp_path / "runs", scene_name(street), "street")
    assert run == tmp_path / "runs" / "street" / scene_name(street)
    record = json.loads((run / "run.json").read_text())
    assert (record["split"], record["train_frames"]) == ("street", 8)
    assert (result.protocol, result.steps) == ("street", STEPS)
    assert load_trained_field(run, device=CPU).split == "street"
    config = train_config(BUDGET)
    assert training_provenance(street, config, CPU, split="street") != training_provenance(
        street, config, CPU)
    with pytest.raises(ValueError, match="no 'train' frames"):
        run_neural3d(read, "train", BUDGET, artefacts_dir=tmp_path / "runs")


def _neural3d_imports(module: str) -> set[str]:
    """The neural3d modules ``module`` imports, transitively (from its source)."""
    seen, todo = set(), [module]
    while todo:
        name = todo.pop()
        if name in seen:
            continue
        seen.add(name)
        path = REPO / (name.replace(".", "/") + ".py")
        if not path.is_file():
            path = REPO / name.replace(".", "/") / "__init__.py"
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith(
                    "neural3d"):
                todo.append(node.module)
            elif isinstance(node, ast.Import):
                todo.extend(a.name for a in node.names if a.name.startswith("neural3d"))
    return seen


def test_training_code_covers_everything_training_imports():
    outside = {m for m in _neural3d_imports("neural3d.train")
               if not any(m == c or m.startswith(c + ".") for c in TRAINING_CODE)}
    assert outside == set(), f"neural3d.train imports {outside}, not in TRAINING_CODE"
