"""Ray-box distances, uniform samples, inverse-CDF sampling and NeuS up-sampling."""

import pytest
import torch

from neural3d.rendering.sampling import neus_upsample, ray_box_near_far, sample_pdf, uniform_samples


def test_ray_box_near_far_closed_form():
    o = torch.tensor([[0.0, 0.0, 5.0], [3.0, 0.0, 5.0], [0.0, 0.0, 0.0]])
    d = torch.tensor([[0.0, 0.0, -1.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]])
    near, far, hit = ray_box_near_far(o, d, torch.tensor([-1.0, -2, -3]), torch.tensor([1.0, 2, 3]))
    assert hit.tolist() == [True, False, True]
    assert near[0].item() == pytest.approx(2.0) and far[0].item() == pytest.approx(8.0)
    assert near[2].item() == pytest.approx(0.0) and far[2].item() == pytest.approx(1.0)
    assert near[1].item() == far[1].item()  # a miss has an empty interval


def test_ray_box_rejects_bad_shapes():
    with pytest.raises(ValueError, match=r"\(R, 3\)"):
        ray_box_near_far(torch.zeros(4, 2), torch.zeros(4, 2), torch.zeros(3), torch.ones(3))


def test_uniform_samples_sorted_within_bounds():
    near, far = torch.tensor([1.0, 2.0]), torch.tensor([3.0, 2.5])
    t = uniform_samples(near, far, 8, perturb=True, generator=torch.Generator().manual_seed(0))
    assert (t[:, 1:] >= t[:, :-1]).all()
    assert (t >= near[:, None]).all() and (t <= far[:, None]).all()
    t = uniform_samples(near, far, 5, perturb=False)
    assert torch.allclose(t[0], torch.tensor([1.0, 1.5, 2.0, 2.5, 3.0]))
    with pytest.raises(ValueError, match="at least 2"):
        uniform_samples(near, far, 1, perturb=False)


def test_sample_pdf_follows_weights():
    edges = torch.linspace(0, 4, 5)[None]  # sections [0,1] [1,2] [2,3] [3,4]
    w = torch.tensor([[0.0, 0.0, 1.0, 0.0]])
    s = sample_pdf(edges, w, 16)
    assert ((s >= 2.0 - 1e-3) & (s <= 3.0 + 1e-3)).float().mean() > 0.99


def test_upsampling_concentrates_at_the_surface():
    o = torch.tensor([[0.0, 0.0, 3.0]])
    d = torch.tensor([[0.0, 0.0, -1.0]])
    t = uniform_samples(torch.tensor([1.5]), torch.tensor([4.5]), 16, perturb=False)
    t2, sdf = neus_upsample(lambda p: p.norm(dim=-1) - 1.0, o, d, t, 16, 4)
    assert t2.shape == (1, 32) and (t2[:, 1:] >= t2[:, :-1]).all()
    new = t2[0][~torch.isin(t2[0], t[0])]
    assert (new - 2.0).abs().max() < 0.2  # the surface is at t = 2
    assert torch.allclose(sdf, (3.0 - t2).abs() - 1.0, atol=1e-5)
