"""Where along each ray the field is evaluated: box near/far, uniform and NeuS up-sampling.

Rays are ``origin + t * dir`` with unit ``dir`` in the normalised frame, so ``t``
is a distance in normalised units. Samples are section edges: the renderer
evaluates the field at the midpoints of consecutive edges.
"""

from __future__ import annotations

from collections.abc import Callable

import torch
from torch import Tensor

_UPSAMPLE_BASE_INV_S = 64.0  # NeuS: fixed sharpness of up-sampling step i is 64 * 2**i


def ray_box_near_far(origins: Tensor, dirs: Tensor, box_min: Tensor, box_max: Tensor,
                     *, min_near: float = 0.0) -> tuple[Tensor, Tensor, Tensor]:
    """Entry and exit distances of rays through an axis-aligned box (slab method).

    ``origins``, ``dirs``: "(R, 3)"; ``box_min``, ``box_max``: "(3,)".
    Returns near "(R,)", far "(R,)" and hit "(R,)" bool; ``near >= min_near``.
    """
    if origins.shape != dirs.shape or origins.ndim != 2 or origins.shape[1] != 3:
        raise ValueError(f"origins and dirs must both be (R, 3), got {tuple(origins.shape)} "
                         f"and {tuple(dirs.shape)}")
    safe = torch.where(dirs.abs() < 1e-12, torch.full_like(dirs, 1e-12), dirs)
    t0 = (box_min - origins) / safe
    t1 = (box_max - origins) / safe
    near = torch.minimum(t0, t1).amax(-1).clamp(min=min_near)
    far = torch.maximum(t0, t1).amin(-1)
    hit = far > near
    return near, torch.where(hit, far, near), hit


def uniform_samples(near: Tensor, far: Tensor, n: int, *, perturb: bool,
                    generator: torch.Generator | None = None) -> Tensor:
    """"(R, n)" sorted distances from near "(R,)" to far "(R,)"; jittered when ``perturb``."""
    if n < 2:
        raise ValueError(f"need at least 2 samples per ray, got {n}")
    s = torch.linspace(0.0, 1.0, n, dtype=near.dtype, device=near.device)
    if perturb:
        jitter = torch.rand((len(near), n), generator=generator, dtype=near.dtype,
                            device=near.device)
        s = (s + (jitter - 0.5) / (n - 1)).clamp(0.0, 1.0)
        s, _ = torch.sort(s, dim=-1)
    return near[:, None] + (far - near)[:, None] * s


def sample_pdf(edges: Tensor, weights: Tensor, n: int) -> Tensor:
    """Deterministic inverse-CDF samples "(R, n)" from piecewise-constant weights.

    ``edges``: "(R, S)" sorted; ``weights``: "(R, S - 1)" one per section.
    """
    w = weights + 1e-5  # a ray with all-zero weights samples uniformly
    cdf = torch.cumsum(w / w.sum(-1, keepdim=True), -1)
    cdf = torch.cat([torch.zeros_like(cdf[:, :1]), cdf], -1)  # (R, S)
    u = torch.linspace(0.0, 1.0, n + 2, dtype=edges.dtype, device=edges.device)[1:-1]
    u = u.expand(len(edges), n).contiguous()
    idx = torch.searchsorted(cdf, u, right=True)
    below = (idx - 1).clamp(0, edges.shape[1] - 1)
    above = idx.clamp(0, edges.shape[1] - 1)
    cdf_lo, cdf_hi = cdf.gather(1, below), cdf.gather(1, above)
    e_lo, e_hi = edges.gather(1, below), edges.gather(1, above)
    denom = torch.where(cdf_hi - cdf_lo < 1e-5, torch.ones_like(cdf_lo), cdf_hi - cdf_lo)
    return e_lo + (u - cdf_lo) / denom * (e_hi - e_lo)


def neus_upsample(sdf_fn: Callable[[Tensor], Tensor], origins: Tensor, dirs: Tensor,
                  t: Tensor, n_importance: int, steps: int) -> tuple[Tensor, Tensor]:
    """NeuS hierarchical sampling: add ``n_importance`` samples near the zero crossing.

    ``sdf_fn``: "(M, 3)" -> "(M,)"; ``t``: "(R, S)" sorted. Each of ``steps`` rounds
    adds ``n_importance // steps`` samples drawn from the weights of a logistic
    density of fixed sharpness 64 * 2**i. Returns t "(R, S + n)" sorted and the SDF
    at those points (no gradient).
    """
    with torch.no_grad():
        sdf = _sdf_along(sdf_fn, origins, dirs, t)
        if steps <= 0 or n_importance <= 0:
            return t, sdf
        per_step = n_importance // steps
        for i in range(steps):
            n = per_step if i < steps - 1 else n_importance - per_step * (steps - 1)
            w = _upsample_weights(t, sdf, _UPSAMPLE_BASE_INV_S * 2**i)
            t_new = sample_pdf(t, w, n)
            sdf_new = _sdf_along(sdf_fn, origins, dirs, t_new)
            t, order = torch.sort(torch.cat([t, t_new], -1), -1)
            sdf = torch.cat([sdf, sdf_new], -1).gather(1, order)
    return t, sdf


def _sdf_along(sdf_fn: Callable[[Tensor], Tensor], origins: Tensor, dirs: Tensor,
               t: Tensor) -> Tensor:
    pts = origins[:, None, :] + dirs[:, None, :] * t[..., None]
    return sdf_fn(pts.reshape(-1, 3)).reshape(t.shape)


def _upsample_weights(t: Tensor, sdf: Tensor, inv_s: float) -> Tensor:
    prev_sdf, next_sdf = sdf[:, :-1], sdf[:, 1:]
    dist = t[:, 1:] - t[:, :-1]
    mid_sdf = (prev_sdf + next_sdf) * 0.5
    cos = (next_sdf - prev_sdf) / (dist + 1e-5)
    prev_cos = torch.cat([torch.zeros_like(cos[:, :1]), cos[:, :-1]], -1)
    # The gentler of two neighbouring slopes, and only where the ray enters a surface.
    cos = torch.minimum(prev_cos, cos).clamp(-1e3, 0.0)
    prev_cdf = torch.sigmoid((mid_sdf - cos * dist * 0.5) * inv_s)
    next_cdf = torch.sigmoid((mid_sdf + cos * dist * 0.5) * inv_s)
    alpha = (prev_cdf - next_cdf + 1e-5) / (prev_cdf + 1e-5)
    trans = torch.cumprod(torch.cat([torch.ones_like(alpha[:, :1]), 1 - alpha + 1e-7], -1), -1)
    return alpha * trans[:, :-1]
