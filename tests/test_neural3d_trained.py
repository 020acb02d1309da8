"""A trained field in world metres: units, shapes, loading errors."""

from dataclasses import replace

import pytest
import torch
from neural3d_scene import write_ring_scene

from neural3d.config import preset_config
from neural3d.field.trained import load_trained_field
from neural3d.train import train

CPU = torch.device("cpu")


@pytest.fixture(scope="module")
def field(box_building, tmp_path_factory):
    root = tmp_path_factory.mktemp("t")
    scene = write_ring_scene(box_building, root / "box", size_px=16, n_train=8, n_eval=0)
    config = replace(preset_config("tiny"), iterations=2, rays_per_batch=16)
    return load_trained_field(train(scene, config, root / "runs", device=CPU), device=CPU)


def test_world_metres_wrap_the_normalisation(field):
    p = torch.tensor([[0.0, 0.0, 4.5], [12.0, -3.0, 2.0]])
    unit = field.normalisation.unit_from_world(p.double()).float()
    expected = field.field.sdf(unit).detach() * field.normalisation.scale_m
    assert torch.allclose(field.sdf_m(p), expected, rtol=1e-5, atol=1e-4)
    assert field.semantic_logits(p).shape == (2, 6)
    rgb = field.rgb(p, torch.tensor([[1.0, 0, 0], [0, 0, -2.0]]))
    assert rgb.shape == (2, 3) and ((rgb >= 0) & (rgb <= 1)).all()
    assert field.class_names[0] == "background" and field.scene_name == "box"
    assert field.box_min_m.shape == (3,) and (field.box_max_m > field.box_min_m).all()


def test_bad_inputs(field, tmp_path):
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        field.sdf_m(torch.zeros(4))
    with pytest.raises(ValueError, match="view_dirs_world"):
        field.rgb(torch.zeros(2, 3), torch.zeros(3, 3))
    with pytest.raises(ValueError, match="not a neural3d run folder"):
        load_trained_field(tmp_path, device=CPU)
