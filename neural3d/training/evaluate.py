"""Held-out evaluation: render eval pixels, report PSNR, semantic accuracy and silhouette IoU.

Full frames are costly (a 512² frame is 262k rays); :func:`eval_pixel_subset`
draws a fixed random subset of each frame's pixels once, so every evaluation of
a run scores the same rays.
"""

from __future__ import annotations

import torch

from neural3d.config import TrainConfig
from neural3d.field.fields import SemanticSDF
from neural3d.rendering.model import render_rays
from neural3d.training.data import Pixels
from neural3d.training.losses import psnr

_EVAL_CHUNK = 2048  # rays per forward pass


def eval_pixel_subset(pixels: Pixels, rays_per_frame: int, *, seed: int) -> Pixels:
    """``rays_per_frame`` random pixels of each frame of ``pixels`` (all of them when 0).

    The draw depends only on ``seed`` and the frame sizes. The subset's ``shapes``
    are ``(1, n)`` per frame (its pixels no longer form images).
    """
    if rays_per_frame <= 0:
        return pixels
    gen = torch.Generator().manual_seed(seed)
    picks, shapes, start = [], [], 0
    for h, w in pixels.shapes:
        n = min(rays_per_frame, h * w)
        picks.append(start + torch.randperm(h * w, generator=gen)[:n])
        shapes.append((1, n))
        start += h * w
    idx = torch.cat(picks).to(pixels.labels.device)
    return Pixels(origins=pixels.origins[idx], dirs=pixels.dirs[idx], rgb=pixels.rgb[idx],
                  labels=pixels.labels[idx],
                  depth_t=None if pixels.depth_t is None else pixels.depth_t[idx],
                  shapes=tuple(shapes))


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
