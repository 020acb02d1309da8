"""Configs: presets, JSON round trip, validation messages."""

import json
from dataclasses import replace

import pytest

from neural3d.config import (
    FieldConfig,
    TrainConfig,
    config_from_dict,
    config_to_dict,
    preset_config,
)


@pytest.mark.parametrize("name", ["paper", "fast", "tiny"])
def test_presets_round_trip_through_json(name):
    c = preset_config(name)
    assert config_from_dict(json.loads(json.dumps(config_to_dict(c)))) == c


def test_paper_preset_follows_the_paper():
    c = preset_config("paper")
    assert c.model.backbone == "mlp" and (c.model.mlp_layers, c.model.mlp_hidden) == (8, 256)
    assert (c.iterations, c.rays_per_batch, c.warmup, c.lr) == (100_000, 2048, 5000, 5e-4)
    assert (c.rgb_weight, c.eikonal_weight, c.semantic_weight) == (1.0, 0.1, 0.5)
    assert c.lr * c.lr_final_factor == pytest.approx(2.5e-5)
    assert preset_config("fast") == TrainConfig() and not TrainConfig().depth_loss


def test_bad_values_and_names():
    with pytest.raises(ValueError, match="unknown preset"):
        preset_config("huge")
    with pytest.raises(ValueError, match="iterations must be positive"):
        TrainConfig(iterations=0)
    with pytest.raises(ValueError, match="unknown backbone"):
        TrainConfig(model=FieldConfig(backbone="tcnn"))
    with pytest.raises(ValueError, match="unknown TrainConfig keys"):
        config_from_dict({**config_to_dict(TrainConfig()), "nonsense": 1})
    with pytest.raises(ValueError, match="image_scale"):
        replace(TrainConfig(), image_scale=2.0)
