"""Positional encoding and the multi-resolution grid: interpolation, hashing, gradients."""

import math

import numpy as np
import pytest
import torch

from neural3d.field.encoding import (
    GridEncoding,
    _FlatGather,
    gather_rows,
    positional_encoding,
    scatter_add_rows,
)


def test_positional_encoding_values():
    x = torch.tensor([[0.5, -1.0]])
    enc = positional_encoding(x, 2)
    assert enc.shape == (1, 2 * 5)
    expected = [0.5, -1.0, math.sin(0.5), math.sin(-1.0), math.sin(1.0), math.sin(-2.0),
                math.cos(0.5), math.cos(-1.0), math.cos(1.0), math.cos(-2.0)]
    assert torch.allclose(enc[0], torch.tensor(expected), atol=1e-6)
    assert positional_encoding(x, 0) is x


def grid(**kw):
    args = dict(levels=3, features=2, min_res=4, max_res=16, log2_table=10)
    args.update(kw)
    return GridEncoding(np.array([-1.0, -1.0, -0.5]), np.array([1.0, 1.0, 0.5]), **args)


def test_trilinear_interpolation_reproduces_linear_functions():
    enc = grid(levels=1, max_res=4)  # one dense level: 4 x 4 x 2 cells
    res = enc.res[0]
    # Write f(i, j, k) = i + 2j + 3k at every vertex; trilinear interpolation is exact for it.
    i, j, k = torch.meshgrid(*[torch.arange(int(r) + 1) for r in res], indexing="ij")
    flat = (i + (res[0] + 1) * (j + (res[1] + 1) * k)).reshape(-1)
    with torch.no_grad():
        enc.table[flat, 0] = (i + 2 * j + 3 * k).reshape(-1).float()
    x = torch.rand(100, 3) * torch.tensor([2.0, 2.0, 1.0]) - torch.tensor([1.0, 1.0, 0.5])
    u = (x - enc.box_min) / enc.box_size * res
    expected = u[:, 0] + 2 * u[:, 1] + 3 * u[:, 2]
    assert torch.allclose(enc(x)[:, 0], expected, atol=1e-4)
    # Its gradient is the constant (1, 2, 3) per cell, times cells per unit length.
    x.requires_grad_(True)
    (grad,) = torch.autograd.grad(enc(x)[:, 0].sum(), x)
    per_unit = res / enc.box_size * torch.tensor([1.0, 2.0, 3.0])
    assert torch.allclose(grad, per_unit.expand_as(grad), rtol=1e-4)


def test_cells_follow_the_box_aspect_and_hash_fine_levels():
    enc = grid(levels=3, min_res=4, max_res=64, log2_table=12)  # 17 * 17 * 9 vertices fit
    assert enc.res[:, 2].tolist() == [2, 8, 32]  # z is half as long as x and y
    assert enc.hashed.tolist() == [False, False, True]
    x = torch.rand(500, 3) * 2 - 1
    out = enc(x)
    assert out.shape == (500, 6) and torch.isfinite(out).all()


def test_flat_gather_backward_matches_indexing():
    table = torch.randn(10, 3, requires_grad=True)
    index = torch.randint(0, 10, (7, 4))
    g = torch.randn(7, 4, 3)
    (a,) = torch.autograd.grad((_FlatGather.apply(table, index) * g).sum(), table)
    (b,) = torch.autograd.grad((table[index] * g).sum(), table)
    assert torch.allclose(a, b, atol=1e-6)


@pytest.mark.parametrize("features", [1, 2, 3, 4])
def test_row_gather_and_its_scatter_match_indexing(features):
    """The wide-element gather is exact; the scatter (a row as one element, or a bincount per
    feature) equals index_add on the rows to 1e-5, in the table's dtype."""
    gen = torch.Generator().manual_seed(features)
    table = torch.randn(50, features, generator=gen)
    index = torch.randint(0, 50, (9, 5, 8), generator=gen)
    assert torch.equal(gather_rows(table, index), table[index])
    grad = torch.randn(9, 5, 8, features, generator=gen)
    expected = torch.zeros_like(table).index_add_(0, index.reshape(-1),
                                                  grad.reshape(-1, features))
    got = scatter_add_rows(grad, index, 50)
    assert got.dtype == table.dtype and torch.allclose(got, expected, atol=1e-5)
    assert torch.equal(scatter_add_rows(grad, index, 50), got)  # deterministic


def test_row_scatter_is_deterministic_with_threads():
    """Many values into few rows, where the order of the additions shows in the last bits:
    every run gives the same bits at 2 threads."""
    gen = torch.Generator().manual_seed(0)
    index = torch.randint(0, 7, (200_000,), generator=gen, dtype=torch.int32)
    grad = torch.randn(200_000, 2, generator=gen)
    threads = torch.get_num_threads()
    torch.set_num_threads(2)
    try:
        runs = {scatter_add_rows(grad, index, 7).numpy().tobytes() for _ in range(5)}
    finally:
        torch.set_num_threads(threads)
    assert len(runs) == 1


def test_no_points_give_a_zero_gradient():
    """A batch whose rays all miss the occupied cells evaluates the grid at no point."""
    enc = grid()
    out = enc(torch.zeros(0, 3))
    assert out.shape == (0, enc.out_dim)
    (g,) = torch.autograd.grad(out.sum(), enc.table, allow_unused=False)
    assert g.shape == enc.table.shape and not g.any()


def test_coarse_to_fine_masks_levels():
    enc = grid()
    with torch.no_grad():
        enc.table.fill_(1.0)
    enc.set_active_levels(1.5)
    out = enc(torch.zeros(1, 3))[0]
    assert torch.allclose(out, torch.tensor([1.0, 1.0, 0.5, 0.5, 0.0, 0.0]))


def test_indices_are_int32_and_a_table_beyond_them_is_refused():
    enc = grid(levels=3, min_res=4, max_res=64, log2_table=12)  # dense, dense, hashed
    index, _ = enc._cells(torch.rand(50, 3) * 2 - 1)
    assert index.dtype == torch.int32
    assert 0 <= int(index.min()) and int(index.max()) < len(enc.table)
    with pytest.raises(ValueError, match="int32"):
        grid(levels=2, min_res=2048, max_res=2048, log2_table=30)  # 2 x 2^30 rows


def test_bad_inputs():
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        grid()(torch.zeros(4, 2))
    with pytest.raises(ValueError, match="levels"):
        grid(levels=0)
