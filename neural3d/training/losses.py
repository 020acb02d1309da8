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


def eikonal(sdf_gradients: Tensor) -> Tensor:
    """Mean of (|grad| - 1)^2 over "(M, 3)" gradients: an SDF has unit-norm gradients."""
    if len(sdf_gradients) == 0:
        return sdf_gradients.sum() * 0.0
    return ((sdf_gradients.norm(dim=-1) - 1.0) ** 2).mean()


def semantic_nll(probs: Tensor, labels: Tensor) -> Tensor:
    """Cross-entropy of rendered class probabilities "(R, C)" against labels "(R,)"."""
    p = probs.gather(1, labels[:, None]).squeeze(1)
    return -torch.log(p.clamp(min=_PROB_FLOOR)).mean()


def mask_bce(accumulation: Tensor, foreground: Tensor) -> Tensor:
    """Binary cross-entropy of ray opacity "(R,)" against the foreground mask "(R,)" bool."""
    acc = accumulation.clamp(1e-4, 1 - 1e-4)
    return F.binary_cross_entropy(acc, foreground.to(acc.dtype))


def depth_l1(depth_t: Tensor, target_t: Tensor) -> Tensor:
    """Mean |depth error| over rays with a target (NaN targets are skipped); "(R,)" each."""
    valid = torch.isfinite(target_t)
    if not valid.any():
        return depth_t.sum() * 0.0
    return (depth_t[valid] - target_t[valid]).abs().mean()


def psnr(rgb: Tensor, target_rgb: Tensor) -> float:
    """Peak signal-to-noise ratio (dB) of colours in [0, 1]."""
    mse = float(((rgb - target_rgb) ** 2).mean())
    return 10.0 * math.log10(1.0 / max(mse, 1e-10))


def total_loss(out: RenderOutput, rgb: Tensor, labels: Tensor, config: TrainConfig, *,
               background_class: int, depth_t: Tensor | None = None
               ) -> tuple[Tensor, dict[str, float]]:
    """Weighted sum of the configured losses and each term's value (for the log)."""
    terms = {
        "rgb": (config.rgb_weight, rgb_l1(out.rgb, rgb)),
        "eikonal": (config.eikonal_weight, eikonal(out.sdf_gradients)),
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
    return total, {k: float(v.detach()) for k, (_, v) in terms.items()}
