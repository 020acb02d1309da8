"""A trained field in world metres: units, shapes, loading errors."""

from dataclasses import replace

import pytest
import torch
from neural3d_scene import write_ring_scene

from envelope.scenes.scene import read_method_input
from neural3d.config import preset_config
from neural3d.field.trained import load_trained_field
from neural3d.train import train

CPU = torch.device("cpu")


@pytest.fixture(scope="module")
def field(box_building, tmp_path_factory):
    root = tmp_path_factory.mktemp("t")
    scene = write_ring_scene(box_building, root / "box", size_px=16, n_train=8, n_eval=0)
    config = replace(preset_config("tiny"), iterations=2, rays_per_batch=16)
    run = train(read_method_input(scene), config, root / "runs", device=CPU)
    return load_trained_field(run, device=CPU)


@pytest.mark.slow
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


def test_queries_split_into_calls_of_chunk_points(field):
    """The one place a field is evaluated in chunks: each network call takes at most
    ``chunk_points`` points, and the answers do not depend on the split."""
    p = torch.rand(10, 3) * 8.0
    whole_sdf, whole_logits = field.sdf_m(p), field.semantic_logits(p)
    whole_rgb = field.rgb(p, -p)
    sizes = []
    hook = field.field.sdf_net.register_forward_pre_hook(lambda _, args: sizes.append(
        len(args[0])))
    try:
        split = (field.sdf_m(p, chunk_points=4), field.semantic_logits(p, chunk_points=3),
                 field.rgb(p, -p, chunk_points=6))
    finally:
        hook.remove()
    assert sizes == [4, 4, 2, 3, 3, 3, 1, 6, 4]
    for got, want in zip(split, (whole_sdf, whole_logits, whole_rgb)):
        torch.testing.assert_close(got, want, rtol=1e-6, atol=1e-6)
    with pytest.raises(ValueError, match="chunk_points"):
        field.sdf_m(p, chunk_points=0)
