"""Wiring only: rays -> samples -> field -> NeuS weights -> rendered quantities."""

from __future__ import annotations

from dataclasses import dataclass

import torch
from torch import Tensor
from torch.profiler import record_function

from neural3d.config import TrainConfig
from neural3d.field.fields import SemanticSDF
from neural3d.rendering.neus import (
    edge_alpha,
    neus_alpha,
    render_accumulation,
    render_depth,
    render_rgb,
    render_semantics,
    weights_from_alpha,
)
from neural3d.rendering.occupancy import OccupancyGrid
from neural3d.rendering.sampling import neus_upsample, ray_box_near_far, uniform_samples


@dataclass(frozen=True)
class RenderOutput:
    """Rendered rays (normalised frame).

    rgb "(R, 3)", semantics "(R, C)" class probabilities, depth "(R,)" distance
    along the ray (0 for the sky), accumulation "(R,)", and the SDF gradients
    "(M, 3)" at every sample the field was evaluated at (for the eikonal term); of
    these the eikonal term counts the rows ``sdf_gradient_mask`` "(M,)" bool marks
    (None: all; the fixed-shape rendering's padded slots are not counted).
    """

    rgb: Tensor
    semantics: Tensor
    depth: Tensor
    accumulation: Tensor
    sdf_gradients: Tensor
    sdf_gradient_mask: Tensor | None = None


def cos_anneal_ratio(config: TrainConfig, step: int) -> float:
    """NeuS cos-anneal ratio at ``step``: 0 -> 1 over ``cos_anneal_steps`` (1 when 0)."""
    if config.cos_anneal_steps <= 0:
        return 1.0
    return min(step / config.cos_anneal_steps, 1.0)


def render_rays(field: SemanticSDF, origins: Tensor, dirs: Tensor, box_min: Tensor,
                box_max: Tensor, config: TrainConfig, *, step: int, training: bool,
                background_class: int, generator: torch.Generator | None = None,
                occupancy: OccupancyGrid | None = None) -> RenderOutput:
    """Render rays "(R, 3)" (unit ``dirs``) through the field inside the box "(3,)".

    ``training``: jitter the uniform samples and keep the graph for the eikonal term.
    Rays that miss the box see only the environment. ``occupancy``: clip each ray
    to its occupied cells first (empty-space skipping).
    """
    with record_function("neural3d.sampling"):
        near, far, hit = ray_box_near_far(origins, dirs, box_min, box_max)
    if occupancy is not None:
        with record_function("neural3d.occupancy"):
            near, far, hit = occupancy.clip_rays(origins, dirs, near, far, hit)
    with record_function("neural3d.sampling"):
        idx = torch.nonzero(hit).squeeze(1)
        o, d = origins[idx], dirs[idx]
        t = uniform_samples(near[idx], far[idx], config.samples_uniform, perturb=training,
                            generator=generator)
        t, sdf_edges = neus_upsample(field.sdf, o, d, t, config.samples_importance,
                                     config.upsample_steps)
        t_mid = (t[:, 1:] + t[:, :-1]) * 0.5
        lengths = (t[:, 1:] - t[:, :-1]).reshape(-1)
        n_rays, n_samples = t_mid.shape
        pts = (o[:, None, :] + d[:, None, :] * t_mid[..., None]).reshape(-1, 3)
        dirs_s = d[:, None, :].expand(n_rays, n_samples, 3).reshape(-1, 3)
        evaluated = None  # rows of the (R * S) samples the field is evaluated at; None = all
        if config.min_estimated_weight > 0:
            with torch.no_grad():
                guess = weights_from_alpha(edge_alpha(sdf_edges, field.inv_s()))
            evaluated = torch.nonzero(guess.reshape(-1) > config.min_estimated_weight).squeeze(1)
            pts, dirs_s, lengths = pts[evaluated], dirs_s[evaluated], lengths[evaluated]
    sdf, feature, grad = field.sdf_feature_gradient(pts, create_graph=training)
    n_all = n_rays * n_samples
    with record_function("neural3d.compositing"):
        cos = (grad * dirs_s).sum(-1)
        alpha = neus_alpha(sdf, cos, lengths, field.inv_s(),
                           cos_anneal_ratio=cos_anneal_ratio(config, step))
        weights = weights_from_alpha(on_all_samples(alpha, evaluated, n_all)
                                     .reshape(n_rays, n_samples))
        kept = None  # rows of the evaluated samples the heads see; None = all
        if config.min_sample_weight > 0:  # light samples are dropped (as if transparent)
            heavy = weights.detach() > config.min_sample_weight
            weights = weights * heavy
            heavy = heavy.reshape(-1) if evaluated is None else heavy.reshape(-1)[evaluated]
            kept = torch.nonzero(heavy).squeeze(1)
    rgb = _at_samples(field.colour, kept, evaluated, n_all, pts, dirs_s, grad, feature)
    logits = _at_samples(field.semantic_logits, kept, evaluated, n_all, feature)
    with record_function("neural3d.compositing"):
        rgb = rgb.reshape(n_rays, n_samples, 3)
        logits = logits.reshape(n_rays, n_samples, field.num_classes)
        background = field.background_rgb(dirs)
        num_classes = field.num_classes
        sem_full = torch.zeros(len(origins), num_classes, dtype=dirs.dtype, device=dirs.device)
        sem_full[:, background_class] = 1.0
        zeros = torch.zeros(len(origins), dtype=dirs.dtype, device=dirs.device)
        return RenderOutput(
            rgb=background.index_copy(0, idx, render_rgb(weights, rgb, background[idx])),
            semantics=sem_full.index_copy(0, idx, render_semantics(weights, logits,
                                                                   background_class)),
            depth=zeros.index_copy(0, idx, render_depth(weights, t_mid)),
            accumulation=zeros.index_copy(0, idx, render_accumulation(weights)),
            sdf_gradients=grad,
        )


def on_all_samples(values: Tensor, rows: Tensor | None, n_all: int) -> Tensor:
    """Values "(M, ...)" at ``rows`` of the ray samples -> "(n_all, ...)", zeros elsewhere
    (samples the field was not evaluated at: transparent); ``values`` when ``rows`` is None."""
    if rows is None:
        return values
    return values.new_zeros(n_all, *values.shape[1:]).index_copy(0, rows, values)


def _at_samples(head, kept: Tensor | None, evaluated: Tensor | None, n_all: int,
                *inputs: Tensor) -> Tensor:
    """``head(*inputs)`` "(n_all, D)" at every ray sample, zeros where the weight is 0.

    ``inputs`` "(M, ...)" are at the ``evaluated`` samples (all when None); the head runs
    only on their ``kept`` rows (all when None).
    """
    out = head(*inputs) if kept is None else head(*(x[kept] for x in inputs))
    rows = kept if evaluated is None else (evaluated if kept is None else evaluated[kept])
    return on_all_samples(out, rows, n_all)
