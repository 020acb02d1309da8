"""A compact U-Net: RGB in, per-pixel class logits out.

Encoder: ``levels`` stages of two 3x3 convolutions (batch norm, ReLU), the channels
doubling and the resolution halving from one stage to the next; decoder: bilinear
upsampling, the encoder's features of that scale concatenated, two convolutions.
Any image size works: the input is padded (edge values) to a multiple of
``2 ** (levels - 1)`` and the output cropped back.
"""

from __future__ import annotations

from dataclasses import dataclass

import torch
from torch import Tensor, nn
from torch.nn import functional as F

from envelope.classes import NUM_CLASSES

# RGB in [0, 1] is centred and scaled to about unit spread before the first convolution.
_INPUT_MEAN, _INPUT_SCALE = 0.5, 4.0


@dataclass(frozen=True)
class UNetConfig:
    """Shape of the network: ``base_channels`` at full resolution, ``levels`` scales
    (``levels - 1`` halvings), ``num_classes`` output channels (the project's classes)."""

    base_channels: int = 16
    levels: int = 5
    num_classes: int = NUM_CLASSES

    def __post_init__(self) -> None:
        if self.base_channels < 1 or self.levels < 1 or self.num_classes < 2:
            raise ValueError(f"a U-Net needs base_channels >= 1, levels >= 1 and at least 2 "
                             f"classes, got {self}")


def _double_conv(c_in: int, c_out: int) -> nn.Sequential:
    return nn.Sequential(
        nn.Conv2d(c_in, c_out, 3, padding=1, bias=False), nn.BatchNorm2d(c_out),
        nn.ReLU(inplace=True),
        nn.Conv2d(c_out, c_out, 3, padding=1, bias=False), nn.BatchNorm2d(c_out),
        nn.ReLU(inplace=True),
    )


class UNet(nn.Module):
    """``forward(rgb)``: ``Float[Tensor, "B 3 H W"]`` in [0, 1] ->
    ``Float[Tensor, "B num_classes H W"]`` logits."""

    def __init__(self, config: UNetConfig = UNetConfig()) -> None:
        super().__init__()
        self.config = config
        widths = [config.base_channels * 2**k for k in range(config.levels)]
        self.down = nn.ModuleList(
            _double_conv(c_in, c_out) for c_in, c_out in zip([3, *widths[:-1]], widths))
        self.up = nn.ModuleList(
            _double_conv(widths[k + 1] + widths[k], widths[k])
            for k in reversed(range(config.levels - 1)))
        self.head = nn.Conv2d(widths[0], config.num_classes, 1)

    def forward(self, rgb: Tensor) -> Tensor:
        if rgb.ndim != 4 or rgb.shape[1] != 3:
            raise ValueError(f"UNet takes (B, 3, H, W) RGB, got shape {tuple(rgb.shape)}")
        h, w = rgb.shape[-2:]
        multiple = 2 ** (self.config.levels - 1)
        pad_h, pad_w = -h % multiple, -w % multiple
        x = (rgb - _INPUT_MEAN) * _INPUT_SCALE
        if pad_h or pad_w:
            x = F.pad(x, (0, pad_w, 0, pad_h), mode="replicate")
        skips = []
        for k, stage in enumerate(self.down):
            if k > 0:
                x = F.max_pool2d(x, 2)
            x = stage(x)
            skips.append(x)
        for stage, skip in zip(self.up, reversed(skips[:-1])):
            x = F.interpolate(x, size=skip.shape[-2:], mode="bilinear", align_corners=False)
            x = stage(torch.cat([x, skip], dim=1))
        return self.head(x)[..., :h, :w]
