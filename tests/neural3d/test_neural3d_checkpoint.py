"""Checkpoints round-trip with weights_only loading; bad files give clear messages."""

import pytest
import torch

from neural3d.field.checkpoint import read_checkpoint, write_checkpoint


def test_round_trip(tmp_path):
    state = {"step": 7, "field": {"w": torch.arange(3.0)}, "train_s": 1.5,
             "generator": torch.Generator().manual_seed(1).get_state()}
    write_checkpoint(tmp_path / "c.pt", state)
    back = read_checkpoint(tmp_path / "c.pt", torch.device("cpu"))
    assert back["step"] == 7 and torch.equal(back["field"]["w"], torch.arange(3.0))
    assert list(tmp_path.iterdir()) == [tmp_path / "c.pt"]  # no temporary left behind


def test_errors(tmp_path):
    with pytest.raises(ValueError, match="does not exist"):
        read_checkpoint(tmp_path / "none.pt", torch.device("cpu"))
    (tmp_path / "bad.pt").write_bytes(b"not a checkpoint")
    with pytest.raises(ValueError, match="cannot be read"):
        read_checkpoint(tmp_path / "bad.pt", torch.device("cpu"))
    write_checkpoint(tmp_path / "x.pt", {"step": 1})
    with pytest.raises(ValueError, match="lacks 'field'"):
        read_checkpoint(tmp_path / "x.pt", torch.device("cpu"))
