"""Wiring of rays through the field: misses see only the environment; shapes."""

import numpy as np
import pytest
import torch

from neural3d.config import preset_config
from neural3d.field.fields import SemanticSDF
from neural3d.rendering.model import cos_anneal_ratio, render_rays


@pytest.mark.slow
def test_render_rays_hits_and_misses():
    from dataclasses import replace

    config = replace(preset_config("tiny"), min_estimated_weight=0.0)  # every sample evaluated
    torch.manual_seed(0)
    field = SemanticSDF(config.model, 4, np.full(3, -1.0), np.full(3, 1.0))  # sphere r = 0.5
    lo, hi = torch.full((3,), -1.0), torch.full((3,), 1.0)
    origins = torch.tensor([[0.0, 0.0, 3.0], [0.0, 3.0, 3.0]])
    dirs = torch.tensor([[0.0, 0.0, -1.0], [0.0, 0.0, -1.0]])  # through the sphere; past the box
    out = render_rays(field, origins, dirs, lo, hi, config, step=0, training=True,
                      background_class=0)
    assert out.rgb.shape == (2, 3) and out.semantics.shape == (2, 4)
    assert out.accumulation[0] > 0.9 and out.accumulation[1] == 0.0
    assert torch.allclose(out.semantics[1], torch.tensor([1.0, 0.0, 0.0, 0.0]))
    assert torch.allclose(out.rgb[1], field.background_rgb(dirs[1:]).detach()[0])
    # The surface of the initial sphere (radius 0.5, +-0.1 wobble) is 2.5 from the origin.
    assert abs(out.depth[0].item() - 2.5) < 0.15
    n = config.samples_uniform + config.samples_importance - 1
    assert out.sdf_gradients.shape == (n, 3)  # only the ray that enters the box is sampled
    assert out.sdf_gradients.requires_grad


def test_cos_anneal_ratio():
    c = preset_config("paper")
    assert cos_anneal_ratio(c, 0) == 0.0 and cos_anneal_ratio(c, c.cos_anneal_steps) == 1.0
    assert cos_anneal_ratio(preset_config("fast"), 0) == 1.0


def test_light_samples_skip_the_heads_and_barely_change_the_render():
    """min_sample_weight drops samples of weight <= w: the colour and semantic heads see
    only the others, and every rendered quantity moves by at most the dropped weight."""
    from dataclasses import replace

    config = preset_config("tiny")
    torch.manual_seed(0)
    field = SemanticSDF(config.model, 4, np.full(3, -1.0), np.full(3, 1.0))  # sphere r = 0.5
    lo, hi = torch.full((3,), -1.0), torch.full((3,), 1.0)
    gen = torch.Generator().manual_seed(0)
    dirs = torch.randn(64, 3, generator=gen)
    dirs = dirs / dirs.norm(dim=1, keepdim=True)
    origins = -2.5 * dirs + 0.3 * torch.randn(64, 3, generator=gen)  # some miss the sphere
    seen = []
    field.colour_net.register_forward_hook(lambda m, args, out: seen.append(len(out)))

    def render(threshold):
        seen.clear()
        out = render_rays(field, origins, dirs, lo, hi, replace(config,
                          min_sample_weight=threshold), step=0, training=False,
                          background_class=0)
        return out, seen[0]

    full, n_all = render(0.0)
    light, n_kept = render(1e-3)
    samples = config.samples_uniform + config.samples_importance - 1
    assert n_all == len(full.sdf_gradients) and 0 < n_kept < n_all
    bound = samples * 1e-3  # at most every sample of a ray dropped at the threshold
    assert (full.accumulation - light.accumulation).abs().max() <= bound
    assert (full.accumulation >= light.accumulation).all()
    assert (full.rgb - light.rgb).abs().max() <= bound
    assert (full.semantics - light.semantics).abs().max() <= bound
    assert torch.allclose(light.semantics.sum(1), torch.ones(64), atol=1e-5)


def test_guessed_light_samples_are_not_evaluated_and_barely_change_the_render():
    """min_estimated_weight: samples whose weight guessed from the SDF at the section ends
    is negligible get no field pass (no SDF gradient, so no eikonal term); what is rendered
    stays close to evaluating every sample: within 2e-3 on average (depth 5e-3), and the
    accumulation within 0.05 on every ray (the guess has no normals, so grazing rays
    differ most)."""
    from dataclasses import replace

    config = preset_config("tiny")
    torch.manual_seed(0)
    field = SemanticSDF(config.model, 4, np.full(3, -1.0), np.full(3, 1.0))  # sphere r = 0.5
    with torch.no_grad():
        field.log_inv_s.fill_(float(np.log(200.0)))  # as sharp as late in training
    lo, hi = torch.full((3,), -1.0), torch.full((3,), 1.0)
    gen = torch.Generator().manual_seed(0)
    dirs = torch.randn(64, 3, generator=gen)
    dirs = dirs / dirs.norm(dim=1, keepdim=True)
    origins = -2.5 * dirs + 0.3 * torch.randn(64, 3, generator=gen)

    def render(guess):
        return render_rays(field, origins, dirs, lo, hi, replace(config,
                           min_estimated_weight=guess), step=0, training=True,
                           background_class=0)

    full, guessed = render(0.0), render(1e-4)
    samples = config.samples_uniform + config.samples_importance - 1
    assert len(full.sdf_gradients) == samples * 64  # every ray enters the box
    assert 0 < len(guessed.sdf_gradients) < 0.6 * len(full.sdf_gradients)
    for a, b, mean in ((full.accumulation, guessed.accumulation, 2e-3),
                       (full.rgb, guessed.rgb, 2e-3), (full.semantics, guessed.semantics, 2e-3),
                       (full.depth, guessed.depth, 5e-3)):
        assert (a - b).abs().mean() < mean
    assert (full.accumulation - guessed.accumulation).abs().max() < 0.05
    assert guessed.accumulation.max() > 0.99  # the sphere is still seen
    # the graph holds together through the scatters: to the sharpness and the SDF decoder
    (guessed.rgb.sum() + (guessed.sdf_gradients.norm(dim=-1) - 1).square().mean()).backward()
    assert field.log_inv_s.grad != 0
    assert field.sdf_net.mlp.linears[0].weight.grad.abs().sum() > 0
