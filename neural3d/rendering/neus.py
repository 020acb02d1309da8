"""NeuS volume rendering: weights computed once, one tiny renderer per quantity.

Each ray is cut into sections between consecutive sample distances; the field
is evaluated at section midpoints. What the weights leave over (``1 -
accumulation``) is the environment at infinity: the background colour for RGB
and the background class for semantics.
"""

from __future__ import annotations

import torch
from torch import Tensor


def neus_alpha(sdf: Tensor, cos_dir_normal: Tensor, section_lengths: Tensor, inv_s: Tensor,
               *, cos_anneal_ratio: float = 1.0) -> Tensor:
    """Opacity "(R, S)" of each section from the SDF at its midpoint (NeuS, Wang et al. 2021).

    ``sdf``, ``cos_dir_normal`` (ray direction . SDF gradient), ``section_lengths``:
    "(R, S)"; ``inv_s``: scalar sharpness of the logistic density. The SDF at the
    section ends is extrapolated along the normal; the opacity is the drop of the
    logistic CDF across the section.
    """
    cos = -(torch.relu(-cos_dir_normal * 0.5 + 0.5) * (1.0 - cos_anneal_ratio)
            + torch.relu(-cos_dir_normal) * cos_anneal_ratio)
    return _cdf_drop(sdf - cos * section_lengths * 0.5, sdf + cos * section_lengths * 0.5, inv_s)


def edge_alpha(sdf_edges: Tensor, inv_s: Tensor | float) -> Tensor:
    """Opacity "(R, S)" of each section from the SDF "(R, S + 1)" at its two ends (NeuS).

    The original NeuS estimate, without normals: the drop of the logistic CDF of
    sharpness ``inv_s`` between a section's ends. Used to guess which sections will
    weigh anything before the field is evaluated with its gradient.
    """
    return _cdf_drop(sdf_edges[:, :-1], sdf_edges[:, 1:], inv_s)


def _cdf_drop(sdf_start: Tensor, sdf_end: Tensor, inv_s: Tensor | float) -> Tensor:
    """Opacity of sections from the SDF at their start and end (any same shape): the relative
    drop of the logistic CDF of sharpness ``inv_s`` across each, in [0, 1]."""
    prev_cdf = torch.sigmoid(sdf_start * inv_s)
    next_cdf = torch.sigmoid(sdf_end * inv_s)
    return ((prev_cdf - next_cdf + 1e-5) / (prev_cdf + 1e-5)).clamp(0.0, 1.0)


def weights_from_alpha(alpha: Tensor) -> Tensor:
    """"(R, S)" rendering weights alpha_i * prod_{j<i} (1 - alpha_j)."""
    trans = torch.cumprod(torch.cat([torch.ones_like(alpha[:, :1]), 1 - alpha + 1e-7], -1), -1)
    return alpha * trans[:, :-1]


def render_accumulation(weights: Tensor) -> Tensor:
    """"(R,)" opacity of each ray: 1 when it hits a surface, 0 when it sees the sky."""
    return weights.sum(-1)


def render_rgb(weights: Tensor, rgb: Tensor, background_rgb: Tensor) -> Tensor:
    """"(R, 3)" colour from per-sample colours "(R, S, 3)" and the sky's "(R, 3)"."""
    acc = render_accumulation(weights)
    return (weights[..., None] * rgb).sum(1) + (1 - acc)[:, None] * background_rgb


def render_semantics(weights: Tensor, logits: Tensor, background_class: int = 0) -> Tensor:
    """"(R, C)" class probabilities from per-sample logits "(R, S, C)".

    Each sample's softmax is mixed by the weights; the left-over part of the ray
    goes to ``background_class``, so rays of sky pixels teach empty space.
    """
    probs = (weights[..., None] * torch.softmax(logits, -1)).sum(1)
    rest = (1 - render_accumulation(weights)).clamp(min=0)
    column = torch.full((1,), background_class, device=probs.device)  # no copy from the host
    return probs.index_add(1, column, rest[:, None])


def render_depth(weights: Tensor, t_mid: Tensor) -> Tensor:
    """"(R,)" expected distance along the ray (0 for the sky), same units as ``t_mid`` "(R, S)"."""
    return (weights * t_mid).sum(-1)
