"""Losses against closed-form values."""

import math
from dataclasses import replace

import pytest
import torch

from neural3d.config import TrainConfig
from neural3d.rendering.model import RenderOutput
from neural3d.training.losses import (
    depth_l1,
    eikonal,
    mask_bce,
    psnr,
    rgb_l1,
    semantic_nll,
    total_loss,
)


def test_closed_forms():
    assert rgb_l1(torch.zeros(2, 3), torch.full((2, 3), 0.5)).item() == pytest.approx(0.5)
    assert eikonal(torch.tensor([[3.0, 4.0, 0.0], [0.0, 0.0, 1.0]])).item() == pytest.approx(8.0)
    assert eikonal(torch.zeros(0, 3)).item() == 0.0
    probs = torch.tensor([[0.25, 0.75], [0.5, 0.5]])
    expected = -(math.log(0.75) + math.log(0.5)) / 2
    assert semantic_nll(probs, torch.tensor([1, 0])).item() == pytest.approx(expected, rel=1e-6)
    assert mask_bce(torch.tensor([0.5]), torch.tensor([True])).item() == pytest.approx(math.log(2))
    nan = float("nan")
    assert depth_l1(torch.tensor([1.0, 2.0]), torch.tensor([1.5, nan])).item() == pytest.approx(0.5)
    assert psnr(torch.zeros(4, 3), torch.full((4, 3), 0.1)) == pytest.approx(20.0)


def test_total_is_the_weighted_sum():
    out = RenderOutput(rgb=torch.zeros(2, 3), semantics=torch.tensor([[0.5, 0.5], [0.5, 0.5]]),
                       depth=torch.zeros(2), accumulation=torch.full((2,), 0.5),
                       sdf_gradients=torch.tensor([[2.0, 0.0, 0.0]]))
    rgb, labels = torch.full((2, 3), 0.2), torch.tensor([0, 1])
    c = TrainConfig()
    total, parts = total_loss(out, rgb, labels, c, background_class=0)
    expected = (0.2 + 0.1 * 1.0 + 0.5 * math.log(2) + c.mask_weight * math.log(2))
    assert total.item() == pytest.approx(expected, rel=1e-5)
    assert set(parts) == {"rgb", "eikonal", "semantic", "mask"}
    with pytest.raises(ValueError, match="no depth"):
        total_loss(out, rgb, labels, replace(c, depth_loss=True), background_class=0)


def test_masked_eikonal_and_depth_count_only_their_rows():
    """The fixed-shape step's padded slots and rays without depth weigh nothing: closed
    forms, and no NaN reaches the gradient from a NaN target."""
    grads = torch.tensor([[3.0, 4.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 5.0]])
    assert eikonal(grads, torch.tensor([True, True, False])).item() == pytest.approx(8.0)
    assert eikonal(grads, torch.zeros(3, dtype=torch.bool)).item() == 0.0
    nan = float("nan")
    depth = torch.tensor([1.0, 2.0], requires_grad=True)
    assert depth_l1(depth, torch.tensor([nan, nan])).item() == 0.0
    depth_l1(depth, torch.tensor([1.5, nan])).backward()
    assert depth.grad.tolist() == [-1.0, 0.0]
