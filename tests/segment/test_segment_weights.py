"""The weights file: round trip, the committed weights (offline, with their training record),
and clear refusals of missing, corrupt, foreign and wrong-class files."""

import io
import json
import socket

import numpy as np
import pytest
import torch

from dataset.presets import preset_recipes
from envelope.classes import CLASS_NAMES
from segment.network import UNet, UNetConfig
from segment.real_sets.splits import committed_splits
from segment.segmenter import predict_labels
from segment.train import TrainConfig
from segment.training_data import EVALUATED_PRESETS
from segment.weights import (
    BUILT_IN_WEIGHTS,
    DEFAULT_WEIGHTS,
    RENDER_WEIGHTS,
    WEIGHTS_FORMAT,
    load_network,
    save_weights,
)

SMALL = UNetConfig(base_channels=4, levels=3)
MAX_COMMITTED_BYTES = 20 * 2**20


def _small_model() -> UNet:
    torch.manual_seed(0)
    model = UNet(SMALL)
    with torch.no_grad():  # non-trivial batch-norm statistics, so that they must round-trip
        for m in model.modules():
            if isinstance(m, torch.nn.BatchNorm2d):
                m.running_mean.uniform_(-0.1, 0.1)
                m.running_var.uniform_(0.5, 1.5)
    return model.eval()


def test_weights_round_trip_with_their_record(tmp_path):
    model = _small_model()
    path = tmp_path / "w.pt"
    save_weights(path, model, {"seed": 3})
    loaded, record = load_network(path)
    assert record == {"seed": 3}
    assert json.loads((tmp_path / "w.json").read_text()) == {"seed": 3}
    assert loaded.config == SMALL and not loaded.training
    rgb = np.random.default_rng(0).integers(0, 256, (40, 50, 3), dtype=np.uint8)
    x = torch.from_numpy(rgb).permute(2, 0, 1)[None].float() / 255
    with torch.no_grad():
        # float16 storage: logits agree to about 1e-2, the classes nearly everywhere
        assert torch.allclose(model(x), loaded(x), atol=5e-2)
    agree = predict_labels(model, rgb) == predict_labels(loaded, rgb)
    assert agree.mean() > 0.99


def _committed(path):
    """The record of committed weights, after the checks every committed file passes: small,
    loaded offline with ``weights_only=True``, the record beside it the same."""
    assert path.stat().st_size <= MAX_COMMITTED_BYTES
    model, record = load_network(path)
    assert model.config.num_classes == len(CLASS_NAMES)
    assert record == json.loads(path.with_suffix(".json").read_text())
    return record


def test_the_committed_render_weights_load_without_network_and_say_how_they_were_made(
        monkeypatch):
    def no_network(*args, **kwargs):
        raise AssertionError("loading the weights tried to open a network connection")

    monkeypatch.setattr(socket, "socket", no_network)
    monkeypatch.setattr(socket, "create_connection", no_network)
    record = _committed(RENDER_WEIGHTS)
    # trained on segtrain buildings only: no building of an evaluated preset, by seed or name
    evaluated = {(r.family, r.seed) for p in EVALUATED_PRESETS for r in preset_recipes(p)}
    used = record["trained_on"] + record["validated_on"]
    assert used and {s["preset"] for s in used} == {"segtrain"}
    families = {r.id: r.family for r in preset_recipes("segtrain")}
    assert not {(families[s["recipe"]], s["recipe_seed"]) for s in used} & evaluated
    assert record["config"]["seed"] == 0 and record["steps_run"] >= 1
    # the training default is the run that made them (docs/segment.md repeats it)
    assert record["config"]["steps"] == record["steps_run"] == TrainConfig().steps
    assert not record["cut_short"]
    assert set(record["provenance"]["code"]) == {"segment", "dataset"}
    assert record["provenance"]["environment"]["torch"]


def test_the_committed_photo_weights_name_every_set_and_licence(monkeypatch):
    def no_network(*args, **kwargs):
        raise AssertionError("loading the weights tried to open a network connection")

    monkeypatch.setattr(socket, "socket", no_network)
    monkeypatch.setattr(socket, "create_connection", no_network)
    assert DEFAULT_WEIGHTS == RENDER_WEIGHTS  # the default (docs/decisions.md, 2026-11-29)
    record = _committed(BUILT_IN_WEIGHTS["photos"])
    sets = record["training_sets"]
    assert set(sets) == {"renders", "labelmefacade", "cmp"}
    assert sets["labelmefacade"]["licence"].startswith("non-commercial research use only")
    # real photos of the train split only; the validation photos of the val split; no test photo
    splits = {s: committed_splits(s) for s in ("labelmefacade", "cmp")}
    real_train = [s for s in record["trained_on"] if "set" in s]
    real_val = [s for s in record["validated_on"] if "set" in s]
    assert {s["set"] for s in real_train} == {s["set"] for s in real_val} == set(splits)
    for s in real_train + real_val:
        assert s["split"] == ("train" if s in real_train else "val")
        assert all(splits[s["set"]][n] == s["split"] for n in s.get("names", []))
    renders = [s for s in record["trained_on"] + record["validated_on"] if "set" not in s]
    assert renders and {s["preset"] for s in renders} == {"segtrain"}
    assert record["cut_short"] == (record["steps_run"] < record["config"]["steps"])
    assert set(record["provenance"]["code"]) == {"segment", "envelope", "dataset"}


def test_a_missing_file_says_how_to_make_one(tmp_path):
    with pytest.raises(ValueError, match=r"not found.*python -m segment.train"):
        load_network(tmp_path / "none.pt")


@pytest.mark.parametrize("content", [b"", b"not a torch archive", "truncated"])
def test_a_corrupt_file_is_refused(tmp_path, content):
    path = tmp_path / "w.pt"
    save_weights(path, _small_model(), {})
    if content == "truncated":
        path.write_bytes(path.read_bytes()[:1000])
    else:
        path.write_bytes(content)
    with pytest.raises(ValueError, match="not a readable segmenter weights file"):
        load_network(path)


def _archive(path, **changes):
    model = _small_model()
    archive = {"format": WEIGHTS_FORMAT, "classes": list(CLASS_NAMES),
               "network": {"base_channels": 4, "levels": 3, "num_classes": len(CLASS_NAMES)},
               "state": model.state_dict(), "record_json": "{}", **changes}
    buf = io.BytesIO()
    torch.save(archive, buf)
    path.write_bytes(buf.getvalue())
    return path


def test_weights_for_other_classes_are_refused(tmp_path):
    other = ["background", "building", "window", "door", "sky", "vegetation"]
    with pytest.raises(ValueError, match=r"trained for the classes \['background', 'building'"):
        load_network(_archive(tmp_path / "w.pt", classes=other))
    # the BlenderProc order (same names, other ids) is other classes too
    reordered = ["background", "wall", "door", "window", "roof", "other"]
    with pytest.raises(ValueError, match="trained for the classes"):
        load_network(_archive(tmp_path / "w.pt", classes=reordered))


def test_foreign_and_mismatched_archives_are_refused(tmp_path):
    with pytest.raises(ValueError, match="not an envelope-bench segmenter weights file"):
        load_network(_archive(tmp_path / "w.pt", format="something-else"))
    torch.save({"weights": torch.zeros(3)}, tmp_path / "plain.pt")
    with pytest.raises(ValueError, match="not an envelope-bench segmenter weights file"):
        load_network(tmp_path / "plain.pt")
    with pytest.raises(ValueError, match="do not fit the network they declare"):
        load_network(_archive(tmp_path / "w.pt", network={"base_channels": 8, "levels": 3}))
    with pytest.raises(ValueError, match="do not fit the network they declare"):
        load_network(_archive(tmp_path / "w.pt", record_json="{not json"))
