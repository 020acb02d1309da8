"""NeuS rendering on analytic SDFs: depth, accumulation and the per-quantity renderers."""

import torch

from neural3d.rendering.neus import (
    edge_alpha,
    neus_alpha,
    render_accumulation,
    render_depth,
    render_rgb,
    render_semantics,
    weights_from_alpha,
)
from neural3d.rendering.sampling import neus_upsample, ray_box_near_far, uniform_samples

INV_S = 1000.0  # sharp density: the rendered surface sits within ~1/INV_S of the zero level


def sphere_sdf(p):
    return p.norm(dim=-1) - 1.0


def sphere_grad(p):
    return p / p.norm(dim=-1, keepdim=True)


BOX_HALF = (0.8, 0.5, 0.6)


def box_sdf(p):
    q = p.abs() - torch.tensor(BOX_HALF)
    return q.clamp(min=0).norm(dim=-1) + q.max(dim=-1).values.clamp(max=0)


def box_grad(p):
    p = p.detach().requires_grad_(True)
    (g,) = torch.autograd.grad(box_sdf(p).sum(), p)
    return g


def render(sdf_fn, grad_fn, origins, dirs):
    near, far, _ = ray_box_near_far(origins, dirs, torch.full((3,), -1.2), torch.full((3,), 1.2))
    t = uniform_samples(near, far, 32, perturb=False)
    t, _ = neus_upsample(sdf_fn, origins, dirs, t, 32, 4)
    mid, length = (t[:, 1:] + t[:, :-1]) / 2, t[:, 1:] - t[:, :-1]
    p = origins[:, None] + dirs[:, None] * mid[..., None]
    alpha = neus_alpha(sdf_fn(p), (grad_fn(p) * dirs[:, None]).sum(-1), length,
                       torch.tensor(INV_S))
    w = weights_from_alpha(alpha)
    return w, mid


def rays_from(eye, targets):
    d = targets - eye
    return eye.expand_as(d).clone(), d / d.norm(dim=-1, keepdim=True)


def test_sphere_depth_and_accumulation():
    gen = torch.Generator().manual_seed(0)
    eye = torch.tensor([0.0, 0.0, 3.0])
    # Targets on the plane z = 0: |xy| < 0.85 hits the unit sphere away from grazing angles,
    # |xy| > 1.15 misses it (the ray passes the sphere at > 0.33 units).
    ang = torch.rand(200, generator=gen) * 6.283
    r_hit = torch.rand(100, generator=gen) * 0.85
    r_miss = 1.15 + torch.rand(100, generator=gen) * 0.3
    r = torch.cat([r_hit, r_miss])
    targets = torch.stack([r * ang.cos(), r * ang.sin(), torch.zeros(200)], -1)
    o, d = rays_from(eye, targets)
    w, mid = render(sphere_sdf, sphere_grad, o, d)
    b = (o * d).sum(-1)
    t_true = -b - (b * b - (o * o).sum(-1) + 1).clamp(min=0).sqrt()
    depth, acc = render_depth(w, mid), render_accumulation(w)
    rel = ((depth - t_true) / t_true)[:100].abs()
    assert rel.max() < 0.01, rel.max()
    assert acc[:100].min() > 0.99
    assert acc[100:].max() < 0.01


def test_box_depth_on_faces():
    eye = torch.tensor([0.3, -0.2, 3.0])
    xy = torch.stack(torch.meshgrid(torch.linspace(-0.6, 0.6, 9), torch.linspace(-0.4, 0.4, 9),
                                    indexing="ij"), -1).reshape(-1, 2)
    targets = torch.cat([xy, torch.full((len(xy), 1), 0.6)], -1)  # points on the top face
    o, d = rays_from(eye, targets)
    w, mid = render(box_sdf, box_grad, o, d)
    t_true = (targets - o).norm(dim=-1)
    assert ((render_depth(w, mid) - t_true) / t_true).abs().max() < 0.01
    assert render_accumulation(w).min() > 0.99


def test_renderers_mix_the_leftover_into_background():
    w = torch.tensor([[0.2, 0.3], [0.0, 0.0]])
    rgb = torch.tensor([[[1.0, 0, 0], [0, 1.0, 0]], [[1.0, 0, 0], [0, 1.0, 0]]])
    sky = torch.tensor([[0, 0, 1.0], [0, 0, 1.0]])
    out = render_rgb(w, rgb, sky)
    assert torch.allclose(out, torch.tensor([[0.2, 0.3, 0.5], [0, 0, 1.0]]))
    logits = torch.tensor([[[10.0, -10, 0], [-10, 10, 0]]] * 2)  # ~one-hot class 0, class 1
    probs = render_semantics(w, logits, background_class=2)
    assert torch.allclose(probs, torch.tensor([[0.2, 0.3, 0.5], [0, 0, 1.0]]), atol=1e-4)
    assert torch.allclose(probs.sum(-1), torch.ones(2), atol=1e-5)


def test_weights_follow_transmittance():
    alpha = torch.tensor([[0.5, 0.5, 1.0]])
    assert torch.allclose(weights_from_alpha(alpha), torch.tensor([[0.5, 0.25, 0.25]]), atol=1e-6)


def test_edge_alpha_telescopes_to_the_logistic_cdf():
    """Along a ray that crosses a plane, sdf(t) = 0.3 - t: the transmittance after the
    sections is the ratio of the logistic CDFs at the two ends (NeuS), whatever the spacing;
    a section that leaves the surface (sdf rising) is transparent."""
    inv_s = 50.0
    t = torch.sort(torch.rand(1, 40, generator=torch.Generator().manual_seed(0)), -1)[0] * 0.6
    t = torch.cat([torch.zeros(1, 1), t, torch.full((1, 1), 0.6)], -1)
    alpha = edge_alpha(0.3 - t, inv_s)
    transmittance = torch.prod(1 - alpha)
    expected = torch.sigmoid(torch.tensor(-0.3 * inv_s)) / torch.sigmoid(torch.tensor(0.3 * inv_s))
    assert abs(float(transmittance) - float(expected)) < 1e-3  # the 1e-5 terms, 42 sections
    assert abs(float(weights_from_alpha(alpha).sum()) - (1 - float(expected))) < 1e-3
    leaving = t - 0.3  # out of the solid: transparent wherever the CDF is not vanishing
    seen = torch.sigmoid(leaving[:, :-1] * inv_s) > 1e-2
    assert seen.sum() > 20 and edge_alpha(leaving, inv_s)[seen].max() < 2e-5  # the 1e-5 terms
