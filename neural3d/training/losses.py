"""Every loss of the semantic SDF, and their weighted sum.

total = rgb_weight * L1(colour) + eikonal_weight * eikonal + semantic_weight * CE(semantics)
      + mask_weight * BCE(accumulation, not background) [+ depth_weight * L1(depth)]
The first three are the paper's (weights 1, 0.1, 0.5); the mask term is the free
silhouette signal of the background class; depth is an optional variant.
"""

from __future__ import annotations

import math

import torch
import torch.nn.functional as F
from torch import Tensor

from neural3d.config import TrainConfig
from neural3d.rendering.model import RenderOutput

_PROB_FLOOR = 1e-6  # keeps log() finite for a class the rendering gives zero probability


def rgb_l1(rgb: Tensor, target_rgb: Tensor) -> Tensor:
    """Mean absolute colour error; "(R, 3)" each."""
    return (rgb - target_rgb).abs().mean()


def eikonal(sdf_gradients: Tensor, mask: Tensor | None = None) -> Tensor:
    """Mean of (|grad| - 1)^2 over "(M, 3)" gradients: an SDF has unit-norm gradients.

    ``mask`` "(M,)" bool: only these rows count (0 when none does); None: every row.
    """
    if len(sdf_gradients) == 0:
        return sdf_gradients.sum() * 0.0
    squares = (sdf_gradients.norm(dim=-1) - 1.0) ** 2
    if mask is None:
        return squares.mean()
    return torch.where(mask, squares, 0.0).sum() / mask.sum().clamp(min=1)


def semantic_nll(probs: Tensor, labels: Tensor) -> Tensor:
    """Cross-entropy of rendered class probabilities "(R, C)" against labels "(R,)"."""
    p = probs.gather(1, labels[:, None]).squeeze(1)
    return -torch.log(p.clamp(min=_PROB_FLOOR)).mean()


def mask_bce(accumulation: Tensor, foreground: Tensor) -> Tensor:
    """Binary cross-entropy of ray opacity "(R,)" against the foreground mask "(R,)" bool."""
    acc = accumulation.clamp(1e-4, 1 - 1e-4)
    return F.binary_cross_entropy(acc, foreground.to(acc.dtype))


def depth_l1(depth_t: Tensor, target_t: Tensor) -> Tensor:
    """Mean |depth error| over rays with a target (NaN targets are skipped; 0 when every
    one is); "(R,)" each. Masked, not selected: no shape or host read depends on the data."""
    valid = torch.isfinite(target_t)
    error = (depth_t - torch.where(valid, target_t, 0.0)).abs()
    return torch.where(valid, error, 0.0).sum() / valid.sum().clamp(min=1)


def psnr(rgb: Tensor, target_rgb: Tensor) -> float:
    """Peak signal-to-noise ratio (dB) of colours in [0, 1]."""
    mse = float(((rgb - target_rgb) ** 2).mean())
    return 10.0 * math.log10(1.0 / max(mse, 1e-10))


def total_loss(out: RenderOutput, rgb: Tensor, labels: Tensor, config: TrainConfig, *,
               background_class: int, depth_t: Tensor | None = None
               ) -> tuple[Tensor, dict[str, Tensor]]:
    """Weighted sum of the configured losses and each term's value "()" (detached, for the
    log; left on the device: reading it is the caller's host sync)."""
    terms = {
        "rgb": (config.rgb_weight, rgb_l1(out.rgb, rgb)),
        "eikonal": (config.eikonal_weight, eikonal(out.sdf_gradients, out.sdf_gradient_mask)),
        "semantic": (config.semantic_weight, semantic_nll(out.semantics, labels)),
    }
    if config.mask_weight > 0:
        terms["mask"] = (config.mask_weight,
                         mask_bce(out.accumulation, labels != background_class))
    if config.depth_loss:
        if depth_t is None:
            raise ValueError("depth_loss is on but the batch has no depth")
        terms["depth"] = (config.depth_weight, depth_l1(out.depth, depth_t))
    total = sum(w * v for w, v in terms.values())
    return total, {k: v.detach() for k, (_, v) in terms.items()}
