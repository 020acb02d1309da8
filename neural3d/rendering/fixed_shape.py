"""A training batch rendered with every shape set by the config: no host syncs, no nonzero.

:func:`neural3d.rendering.model.render_rays` renders only the rays that hit (the box, or
the occupancy grid's cells) and evaluates the field only at the samples it keeps
(``min_estimated_weight``), picked with ``torch.nonzero``: its tensors' shapes follow the
data and it reads values on the host, so its step cannot be captured as a CUDA graph.
:func:`render_rays_fixed_shape` renders the same quantities for training
(``TrainConfig.sample_buffer`` > 0) with shapes set by the batch size and the config:

- every ray is sampled; a ray that hits nothing has no candidate sample, so its weights
  are 0 and it renders the environment, as in ``render_rays``;
- the candidates are the samples ``render_rays`` evaluates: those of a ray that hits,
  guessed heavier than ``min_estimated_weight`` (all of them when that is 0). The field,
  with its gradient, is evaluated at ``sample_buffer`` slots (:func:`sample_slots`):
  the candidates, heaviest guess first; slots left over hold the first non-candidates,
  masked out (alpha 0, no eikonal term); candidates beyond the slots are dropped,
  lightest guess first, and counted;
- the colour and semantic heads run at every slot; light samples
  (``min_sample_weight``) get weight 0, as in ``render_rays``;
- the occupancy grid probes every ray at a count fixed by the box
  (``OccupancyGrid.probes_for_box``, at least the batch-dependent count).

Rays that hit are put first (in order) so that the k-th of them draws the k-th row of
the sample jitter, as ``render_rays``' draw over the hit rays does: with slots for every
candidate and no occupancy grid (or one that keeps the whole box) the two give the same
loss and gradients to rounding (tests/neural3d/test_neural3d_fixed_shape.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import torch
from torch import Tensor
from torch.profiler import record_function

from neural3d.config import TrainConfig
from neural3d.field.fields import SemanticSDF
from neural3d.rendering.model import RenderOutput, cos_anneal_ratio, on_all_samples
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
class SampleSlots:
    """The N samples of a batch's M = R * S the field is evaluated at (N fixed, M >= N)."""

    rows: Tensor  # "(N,)" int64 rows of the flattened "(R, S)" samples, ascending
    valid: Tensor  # "(N,)" bool: the slot holds a candidate (else padding, masked out)
    dropped: Tensor  # "()" int64: candidates beyond the N slots, left out


def sample_slots(candidate: Tensor, guess: Tensor, n_slots: int) -> SampleSlots:
    """``n_slots`` (at most M) of the samples "(M,)": candidates first, heaviest ``guess``
    (guessed rendering weight, in [0, 1]) first, ties in order of position (a stable sort:
    the choice is deterministic)."""
    score = torch.where(candidate, guess, -1.0)
    chosen = torch.sort(score, descending=True, stable=True).indices[:n_slots]
    rows = torch.sort(chosen).values
    return SampleSlots(rows, candidate[rows], (candidate.sum() - n_slots).clamp(min=0))


def render_rays_fixed_shape(field: SemanticSDF, origins: Tensor, dirs: Tensor,
                            box_min: Tensor, box_max: Tensor, config: TrainConfig, *,
                            step: int, background_class: int,
                            generator: torch.Generator | None = None,
                            occupancy: OccupancyGrid | None = None
                            ) -> tuple[RenderOutput, Tensor]:
    """Render training rays "(R, 3)" (unit ``dirs``) as ``render_rays(training=True)`` does,
    with ``config.sample_buffer`` sample slots; also the count "()" of dropped candidates.

    Every tensor's shape depends on R and the config only. ``sdf_gradients`` are the
    slots' "(N, 3)", ``sdf_gradient_mask`` marks the candidates among them.
    """
    with record_function("neural3d.sampling"):
        near, far, hit = ray_box_near_far(origins, dirs, box_min, box_max)
    if occupancy is not None:
        with record_function("neural3d.occupancy"):
            near, far, hit = occupancy.clip_rays(origins, dirs, near, far, hit,
                                                 n_probe=occupancy.probes_for_box)
    with record_function("neural3d.sampling"):
        order = torch.argsort((~hit).to(torch.uint8), stable=True)  # rays that hit first
        hit, o, d = hit[order], origins[order], dirs[order]
        t = uniform_samples(near[order], far[order], config.samples_uniform, perturb=True,
                            generator=generator)
        t, sdf_edges = neus_upsample(field.sdf, o, d, t, config.samples_importance,
                                     config.upsample_steps)
        t_mid = (t[:, 1:] + t[:, :-1]) * 0.5
        n_rays, n_samples = t_mid.shape
        with torch.no_grad():
            guess = weights_from_alpha(edge_alpha(sdf_edges, field.inv_s()))
        candidate = hit[:, None].expand(n_rays, n_samples)
        if config.min_estimated_weight > 0:
            candidate = candidate & (guess > config.min_estimated_weight)
        n_all = n_rays * n_samples
        slots = sample_slots(candidate.reshape(-1), guess.reshape(-1),
                             min(config.sample_buffer, n_all))
        pts = (o[:, None, :] + d[:, None, :] * t_mid[..., None]).reshape(-1, 3)[slots.rows]
        dirs_s = d[:, None, :].expand(n_rays, n_samples, 3).reshape(-1, 3)[slots.rows]
        lengths = (t[:, 1:] - t[:, :-1]).reshape(-1)[slots.rows]
    sdf, feature, grad = field.sdf_feature_gradient(pts, create_graph=True)
    with record_function("neural3d.compositing"):
        cos = (grad * dirs_s).sum(-1)
        alpha = neus_alpha(sdf, cos, lengths, field.inv_s(),
                           cos_anneal_ratio=cos_anneal_ratio(config, step))
        alpha = torch.where(slots.valid, alpha, 0.0)
        weights = weights_from_alpha(on_all_samples(alpha, slots.rows, n_all)
                                     .reshape(n_rays, n_samples))
        if config.min_sample_weight > 0:  # light samples are dropped (as if transparent)
            weights = weights * (weights.detach() > config.min_sample_weight)
    rgb = on_all_samples(field.colour(pts, dirs_s, grad, feature), slots.rows, n_all)
    logits = on_all_samples(field.semantic_logits(feature), slots.rows, n_all)
    with record_function("neural3d.compositing"):
        rgb = rgb.reshape(n_rays, n_samples, 3)
        logits = logits.reshape(n_rays, n_samples, field.num_classes)
        background = field.background_rgb(dirs)
        back = torch.argsort(order)  # the rays' own order again
        out = RenderOutput(
            rgb=render_rgb(weights, rgb, background[order])[back],
            semantics=render_semantics(weights, logits, background_class)[back],
            depth=render_depth(weights, t_mid)[back],
            accumulation=render_accumulation(weights)[back],
            sdf_gradients=grad,
            sdf_gradient_mask=slots.valid,
        )
    return out, slots.dropped
