"""One training step of the semantic SDF, and what it needs: optimiser, schedule, EMA, grid.

:func:`train_step` is the only training step: ``neural3d.train`` loops over it
and ``bench/neural3d.py`` times it. With ``config.sample_buffer`` > 0 it renders the
batch with :func:`neural3d.rendering.fixed_shape.render_rays_fixed_shape` (every shape
fixed, no host read until the optimiser has stepped); otherwise with
:func:`neural3d.rendering.model.render_rays`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import partial

import torch
from torch.profiler import record_function

from neural3d.config import TrainConfig
from neural3d.field.fields import SemanticSDF
from neural3d.rendering.fixed_shape import render_rays_fixed_shape
from neural3d.rendering.model import RenderOutput, render_rays
from neural3d.rendering.occupancy import OccupancyGrid
from neural3d.training.data import Pixels
from neural3d.training.losses import total_loss


def lr_factor(step: int, config: TrainConfig) -> float:
    """Learning-rate multiplier: linear warm-up, then cosine decay to ``lr_final_factor``."""
    if step < config.warmup:
        return (step + 1) / config.warmup
    progress = min((step - config.warmup) / max(config.iterations - config.warmup, 1), 1.0)
    return config.lr_final_factor + (1 - config.lr_final_factor) * 0.5 * (
        1 + math.cos(math.pi * progress))


def make_optimizer(field: torch.nn.Module, config: TrainConfig
                   ) -> tuple[torch.optim.Adam, torch.optim.lr_scheduler.LambdaLR]:
    """Adam over all of ``field``'s parameters and its warm-up + cosine schedule.

    Adam is the fused implementation on CPU and CUDA: on the grid's 3.7 M-entry
    table one CPU step takes a tenth of the default (foreach) step's time.
    """
    params = list(field.parameters())
    fused = all(p.device.type in ("cpu", "cuda") for p in params)
    optimizer = torch.optim.Adam(params, lr=config.lr, betas=(0.9, 0.99), eps=1e-15,
                                 fused=fused)
    return optimizer, torch.optim.lr_scheduler.LambdaLR(optimizer, partial(lr_factor,
                                                                           config=config))


@dataclass(frozen=True)
class StepResult:
    """One training step: the loss (detached), its weighted parts, the batch and its render."""

    loss: float
    parts: dict[str, float]
    pixel_index: torch.Tensor  # "(R,)" rows of the pixels the batch used
    render: RenderOutput
    dropped_samples: int = 0  # candidates the fixed-shape step had no slot for (else 0)


@torch.no_grad()
def update_ema(average: torch.nn.Module, field: torch.nn.Module, decay: float) -> None:
    """``average`` <- decay * average + (1 - decay) * field (parameters); buffers copied."""
    torch._foreach_lerp_(list(average.parameters()), list(field.parameters()), 1.0 - decay)
    for a, b in zip(average.buffers(), field.buffers()):
        a.copy_(b)


def make_occupancy(config: TrainConfig, box_min: torch.Tensor, box_max: torch.Tensor
                   ) -> OccupancyGrid | None:
    """The run's occupancy grid over the box "(3,)", or None when ``occupancy_resolution`` is 0."""
    if config.occupancy_resolution == 0:
        return None
    return OccupancyGrid(box_min, box_max, config.occupancy_resolution)


def train_step(field: SemanticSDF, optimizer: torch.optim.Optimizer,
               scheduler: torch.optim.lr_scheduler.LRScheduler | None, pixels: Pixels,
               box_min: torch.Tensor, box_max: torch.Tensor, config: TrainConfig, *,
               step: int, background_class: int, generator: torch.Generator,
               occupancy: OccupancyGrid | None = None,
               average: torch.nn.Module | None = None) -> StepResult:
    """One optimisation step at ``step`` (the only training step; the bench calls it too).

    Draws ``config.rays_per_batch`` pixels with ``generator``, renders them, takes
    the weighted loss and one optimizer (and scheduler, if given) step. With an
    ``occupancy`` grid, rays skip empty space; the grid is refreshed from the SDF
    at ``occupancy_start`` and every ``occupancy_every`` steps after. With an
    ``average`` (a copy of ``field``), it follows ``field`` by ``config.ema_decay``.
    ``config.sample_buffer`` > 0: the fixed-shape rendering (module docstring); the
    values it reports are read on the host only after the optimiser and EMA updates.
    Each part runs under a ``neural3d.<part>`` profiler label (bench/neural3d_profile.py).
    """
    field.set_step(step)
    if occupancy is not None and step >= config.occupancy_start and (
            step - config.occupancy_start) % config.occupancy_every == 0:
        with record_function("neural3d.occupancy"):
            occupancy.update_from_sdf(field.sdf,
                                      margin=config.occupancy_margin_cells * occupancy.cell)
    with record_function("neural3d.rays"):
        idx = torch.randint(len(pixels), (config.rays_per_batch,), generator=generator,
                            device=pixels.rgb.device)
        origins, dirs, rgb, labels = (pixels.origins[idx], pixels.dirs[idx], pixels.rgb[idx],
                                      pixels.labels[idx])
        depth_t = pixels.depth_t[idx] if pixels.depth_t is not None else None
    dropped = None
    if config.sample_buffer > 0:
        out, dropped = render_rays_fixed_shape(field, origins, dirs, box_min, box_max, config,
                                               step=step, background_class=background_class,
                                               generator=generator, occupancy=occupancy)
    else:
        out = render_rays(field, origins, dirs, box_min, box_max, config, step=step,
                          training=True, background_class=background_class,
                          generator=generator, occupancy=occupancy)
    with record_function("neural3d.losses"):
        loss, parts = total_loss(out, rgb, labels, config, background_class=background_class,
                                 depth_t=depth_t)
    with record_function("neural3d.backward"):
        optimizer.zero_grad(set_to_none=True)
        loss.backward()
    with record_function("neural3d.optimiser"):
        optimizer.step()
        if scheduler is not None:
            scheduler.step()
    if average is not None:
        with record_function("neural3d.weight averaging"):
            update_ema(average, field, config.ema_decay)
    return StepResult(float(loss.detach()), {k: float(v) for k, v in parts.items()}, idx, out,
                      0 if dropped is None else int(dropped))
