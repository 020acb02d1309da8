"""Held-out evaluation: render the eval frames, report PSNR and semantic accuracy."""

from __future__ import annotations

import torch

from neural3d.config import TrainConfig
from neural3d.data import Pixels
from neural3d.fields import SemanticSDF
from neural3d.losses import psnr
from neural3d.model import render_rays

_EVAL_CHUNK = 2048  # rays per forward pass


def render_pixels(field: SemanticSDF, pixels: Pixels, box_min: torch.Tensor,
                  box_max: torch.Tensor, config: TrainConfig, *, step: int,
                  background_class: int) -> tuple[torch.Tensor, torch.Tensor]:
    """RGB "(P, 3)" and class probabilities "(P, C)" of every pixel, no gradients kept."""
    rgb, sem = [], []
    was_training = field.training
    field.eval()
    try:
        with torch.no_grad():  # normals still come from the SDF's gradient inside the field
            for start in range(0, len(pixels), _EVAL_CHUNK):
                sl = slice(start, start + _EVAL_CHUNK)
                out = render_rays(field, pixels.origins[sl], pixels.dirs[sl], box_min, box_max,
                                  config, step=step, training=False,
                                  background_class=background_class)
                rgb.append(out.rgb)
                sem.append(out.semantics)
    finally:
        field.train(was_training)
    return torch.cat(rgb), torch.cat(sem)


def evaluate(field: SemanticSDF, pixels: Pixels, box_min: torch.Tensor, box_max: torch.Tensor,
             config: TrainConfig, *, step: int, background_class: int) -> dict[str, float]:
    """``{"psnr": dB, "semantic_accuracy": fraction, "mask_iou": IoU}`` over ``pixels``.

    ``mask_iou`` compares the rendered and true building silhouettes (non-background).
    """
    rgb, sem = render_pixels(field, pixels, box_min, box_max, config, step=step,
                             background_class=background_class)
    pred = sem.argmax(-1)
    fg_pred, fg_true = pred != background_class, pixels.labels != background_class
    union = (fg_pred | fg_true).sum().item()
    return {
        "psnr": psnr(rgb, pixels.rgb),
        "semantic_accuracy": (pred == pixels.labels).float().mean().item(),
        "mask_iou": (fg_pred & fg_true).sum().item() / union if union else 1.0,
    }
