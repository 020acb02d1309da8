"""Input encodings: NeRF positional encoding and a multi-resolution grid in pure PyTorch.

The grid follows instant-ngp: level ``l`` has resolution ``min_res * b**l``; a
level whose vertices fit the table is stored densely (no collisions), finer
levels are hashed. All levels live in one flat table so the lookup is a single
gather. On CPU the gather reads each row as one wide element through
``index_select`` and its backward adds each row as one element with ``index_add_``
(together about 5x faster than advanced indexing and ``index_add``); the eight trilinear
weights are built from per-axis factors without broadcasting, so no backward
pass has to reduce over broadcast axes (docs/decisions.md, "grid encoding
speed"; figures in docs/measurements/neural3d-training.md). Corner indices are int32 and
hashed with a mask (the table is a power of two), about 2x cheaper to compute than int64
with a modulo.
"""

from __future__ import annotations

import math

import numpy as np
import torch
from torch import Tensor, nn
from torch.autograd.function import once_differentiable
from torch.profiler import record_function

_PRIMES = (1, 2654435761, 805459861)  # instant-ngp's spatial hash


def positional_encoding(x: Tensor, frequencies: int) -> Tensor:
    """"(N, D)" -> "(N, D * (1 + 2 * F))": x, sin(2^k x), cos(2^k x) for k < F = frequencies."""
    if frequencies == 0:
        return x
    scales = 2.0 ** torch.arange(frequencies, dtype=x.dtype, device=x.device)
    xs = (x[..., None, :] * scales[:, None]).flatten(-2)
    return torch.cat([x, torch.sin(xs), torch.cos(xs)], dim=-1)


_ROW_DTYPES = {(torch.float32, 1): torch.float32, (torch.float32, 2): torch.float64,
               (torch.float32, 4): torch.complex128}


def gather_rows(table: Tensor, index: Tensor) -> Tensor:
    """``table[index]`` for a "(T, F)" table and an integer index of any shape -> "(*index, F)".

    A float32 row of 1, 2 or 4 features is read as one 4-, 8- or 16-byte element,
    so ``index_select`` copies one element per row (no autograd).
    """
    rows, features = table.shape
    wide = _ROW_DTYPES.get((table.dtype, features))
    flat = index.reshape(-1)
    if wide is None or not table.is_contiguous():
        return table.index_select(0, flat).reshape(*index.shape, features)
    packed = table.view(wide).reshape(rows)
    return packed.index_select(0, flat).view(table.dtype).reshape(*index.shape, features)


_PAIR_DTYPES = {torch.float32: torch.complex64, torch.float64: torch.complex128}


def scatter_add_rows(grad: Tensor, index: Tensor, rows: int) -> Tensor:
    """Adjoint of :func:`gather_rows` (its backward): "(*index, F)" -> "(rows, F)", the
    sum of the values gathered from each row.

    On CPU a row of 1 or 2 features is added as one element (a 2-feature row as one
    complex number) by ``index_add_``, whose loop over a 1-D tensor is sequential, so
    deterministic; its cost is the scatter, not the table (about 2x faster than a
    ``bincount`` per feature, which writes a float64 table of every row per feature;
    ``index_add_`` on "(rows, 2)" rows is about 5x slower than either). Elsewhere, or
    with more features: a ``bincount`` per feature, accumulated in float64.
    """
    flat = index.reshape(-1)
    features = grad.shape[-1]
    values = grad.reshape(len(flat), features)  # no -1: N may be 0
    if values.device.type == "cpu" and features <= 2 and values.dtype in _PAIR_DTYPES:
        out = values.new_zeros(rows, features)
        if features == 1:
            out.view(rows).index_add_(0, flat, values.reshape(-1))
        else:
            pair = _PAIR_DTYPES[values.dtype]
            out.view(pair).view(rows).index_add_(0, flat, values.contiguous().view(pair)
                                                  .view(len(flat)))
        return out
    sums = [torch.bincount(flat, weights=g, minlength=rows) for g in values.unbind(1)]
    return torch.stack(sums, 1).to(grad.dtype)


class _FlatGather(torch.autograd.Function):
    """``table[index]`` (:func:`gather_rows`) with a :func:`scatter_add_rows` backward."""

    @staticmethod
    def forward(ctx, table: Tensor, index: Tensor) -> Tensor:  # noqa: D102
        ctx.save_for_backward(index)
        ctx.rows = table.shape[0]
        return gather_rows(table, index)

    @staticmethod
    @once_differentiable
    def backward(ctx, grad: Tensor) -> tuple[Tensor, None]:  # noqa: D102
        (index,) = ctx.saved_tensors
        return scatter_add_rows(grad, index, ctx.rows), None


class GridEncoding(nn.Module):
    """Multi-resolution grid over an axis-aligned box of the normalised frame.

    Per-axis resolutions follow the box's aspect ratio, so cells are cubes.
    ``forward``: "(N, 3)" points -> "(N, levels * features)"; points outside the
    box are clamped to it. Coarse-to-fine: :meth:`set_active_levels` fades finer
    levels in (their features are multiplied by a 0..1 ramp).
    """

    def __init__(self, box_min: np.ndarray, box_max: np.ndarray, *, levels: int, features: int,
                 min_res: int, max_res: int, log2_table: int) -> None:
        super().__init__()
        if levels < 1 or features < 1 or min_res < 2 or max_res < min_res:
            raise ValueError(
                f"grid needs levels >= 1, features >= 1 and 2 <= min_res <= max_res, got "
                f"{levels}, {features}, {min_res}, {max_res}"
            )
        lo, hi = np.asarray(box_min, float), np.asarray(box_max, float)
        extent = hi - lo
        growth = math.exp((math.log(max_res) - math.log(min_res)) / max(levels - 1, 1))
        table = 2**log2_table
        res, offsets, hashed = [], [], []
        total = 0
        for level in range(levels):
            r = min_res * growth**level
            r_axes = np.maximum(2, np.ceil(r * extent / extent.max())).astype(np.int64)
            n_vertices = int(np.prod(r_axes + 1))
            size = min(n_vertices, table)
            res.append(r_axes)
            offsets.append(total)
            hashed.append(n_vertices > table)
            total += size
        self.levels, self.features = levels, features
        self.out_dim = levels * features
        if total >= 2**31:
            raise ValueError(f"grid table of {total} rows does not fit int32 indices; lower "
                             "log2_table or levels")
        # Buffers derived from the config are not saved: a checkpoint holds learnt weights.
        # Indices are int32 (about 2x faster to compute than int64 on CPU); only the hashed
        # levels' products with the primes need int64.
        i32 = torch.int32
        self.register_buffer("box_min", torch.tensor(lo, dtype=torch.float32), persistent=False)
        self.register_buffer("box_size", torch.tensor(extent, dtype=torch.float32),
                             persistent=False)
        self.register_buffer("res", torch.tensor(np.stack(res), dtype=i32),
                             persistent=False)  # (L, 3)
        self.register_buffer("offsets", torch.tensor(offsets, dtype=i32), persistent=False)
        self.register_buffer("hashed", torch.tensor(hashed), persistent=False)  # (L,) bool
        self.hash_mask = table - 1  # hashed levels fill the table, a power of two
        self.n_dense = int(sum(not h for h in hashed))
        if any(hashed[: self.n_dense]):
            raise AssertionError("dense levels must come first")  # resolution grows per level
        strides = [[1, r[0] + 1, (r[0] + 1) * (r[1] + 1)] for r in res]
        self.register_buffer("strides", torch.tensor(strides, dtype=i32),
                             persistent=False)  # (L, 3)
        self.register_buffer("primes", torch.tensor(_PRIMES), persistent=False)  # int64
        self.register_buffer("two", torch.arange(2, dtype=i32), persistent=False)
        self.register_buffer("level_mask", torch.ones(levels), persistent=False)
        self.table = nn.Parameter(torch.empty(total, features).uniform_(-1e-4, 1e-4))

    def set_active_levels(self, active: float) -> None:
        """Switch on the ``active`` coarsest levels (fractional: the next fades in)."""
        ramp = (active - torch.arange(self.levels, device=self.level_mask.device)).clamp(0, 1)
        self.level_mask.copy_(ramp)

    def forward(self, x: Tensor) -> Tensor:
        index, frac = self._cells(x)
        weights = _trilinear_weights(frac)  # (N, L, 8)
        with record_function("neural3d.encoding gather"):
            values = _FlatGather.apply(self.table, index)  # (N, L, 8, F)
        feats = torch.stack([(weights * values[..., f]).sum(-1)
                             for f in range(self.features)], -1)  # (N, L, F)
        return (feats * self.level_mask[:, None]).reshape(len(x), self.out_dim)

    def _cells(self, x: Tensor) -> tuple[Tensor, Tensor]:
        """Table rows "(N, L, 8)" (int32) of each point's cell corners, corner
        c = 4 bx + 2 by + bz, and the point's position in its cell "(N, L, 3)" in [0, 1],
        differentiable in ``x``; points outside the box are clamped to it."""
        if x.ndim != 2 or x.shape[1] != 3:
            raise ValueError(f"GridEncoding expects (N, 3) points, got {tuple(x.shape)}")
        u = ((x - self.box_min) / self.box_size).clamp(0, 1)  # (N, 3) in the unit cube
        pos = u[:, None, :] * self.res  # (N, L, 3)
        i0 = pos.detach().floor().int().clamp(max=self.res - 1)
        ic = i0[..., None] + self.two  # (N, L, 3, 2)
        nd = self.n_dense
        parts = []
        if nd > 0:
            a = ic[:, :nd] * self.strides[:nd, :, None]
            parts.append(a[:, :, 0, :, None, None] + a[:, :, 1, None, :, None]
                         + a[:, :, 2, None, None, :])
        if nd < self.levels:
            a = ic[:, nd:].long() * self.primes[:, None]
            h = a[:, :, 0, :, None, None] ^ a[:, :, 1, None, :, None] ^ a[:, :, 2, None, None, :]
            parts.append((h & self.hash_mask).int())
        index = torch.cat(parts, 1) + self.offsets[:, None, None, None]  # (N, L, 2, 2, 2)
        return index.reshape(len(x), self.levels, 8), pos - i0


def _trilinear_weights(frac: Tensor) -> Tensor:
    """"(N, L, 3)" position in the cell -> "(N, L, 8)" weight of corner c = 4 bx + 2 by + bz."""
    fx, fy, fz = frac.unbind(-1)
    gx, gy, gz = 1 - fx, 1 - fy, 1 - fz
    xy = (gx * gy, gx * fy, fx * gy, fx * fy)
    return torch.stack([a * b for a in xy for b in (gz, fz)], -1)


class PositionalInput(nn.Module):
    """The ``mlp`` backbone's input: "(N, 3)" -> "(N, out_dim)" = [x, sin, cos] (NeRF)."""

    def __init__(self, frequencies: int) -> None:
        super().__init__()
        self.frequencies = frequencies
        self.out_dim = 3 * (1 + 2 * frequencies)

    def set_step(self, step: int) -> None:
        """No schedule: the encoding is fixed."""

    def forward(self, x: Tensor) -> Tensor:
        with record_function("neural3d.encoding"):
            return positional_encoding(x, self.frequencies)


class GridInput(nn.Module):
    """The ``grid`` backbone's input: "(N, 3)" -> "(N, out_dim)" = [x, grid features].

    ``set_step`` runs the coarse-to-fine schedule: ``start_levels`` levels on at
    step 0, all of them after ``ramp_steps``.
    """

    def __init__(self, grid: GridEncoding, *, start_levels: int, ramp_steps: int) -> None:
        super().__init__()
        self.grid = grid
        self.start_levels, self.ramp_steps = start_levels, ramp_steps
        self.out_dim = 3 + grid.out_dim

    def set_step(self, step: int) -> None:
        """Switch on the levels the coarse-to-fine schedule allows at ``step``."""
        ramp = min(step / max(self.ramp_steps, 1), 1.0)
        levels = self.grid.levels
        self.grid.set_active_levels(self.start_levels + ramp * (levels - self.start_levels))

    def forward(self, x: Tensor) -> Tensor:
        with record_function("neural3d.encoding"):
            return torch.cat([x, self.grid(x)], dim=-1)

