"""A compact U-Net: RGB in, per-pixel class logits out.

Encoder: ``levels`` stages of two 3x3 convolutions (batch norm, ReLU), the channels
doubling and the resolution halving from one stage to the next; decoder: bilinear
upsampling, the encoder's features of that scale concatenated, two convolutions.
Any image size works: the input is padded (edge values) to a multiple of
``2 ** (levels - 1)`` (times ``stem_stride``) and the output cropped back.

With ``stem_stride`` 2 a strided convolution first halves the resolution, the U-Net runs on
half-resolution features (twice the channels for the same cost) and its logits are
upsampled (bilinear) to the input's size. ``working_long_side_px`` is not the network's
shape but how it is used: :func:`segment.segmenter.predict_logits` scales every image so
that its long side has that many pixels (the scale it was trained at) and its logits back.
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
    """Shape of the network: ``base_channels`` at the first scale, ``levels`` scales
    (``levels - 1`` halvings), ``num_classes`` output channels (the project's classes);
    ``stem_stride`` 1 (the U-Net at full resolution) or 2 (a strided stem first);
    ``working_long_side_px``: the long side images are scaled to before the network
    (``None``: each image at its own size)."""

    base_channels: int = 16
    levels: int = 5
    num_classes: int = NUM_CLASSES
    stem_stride: int = 1
    working_long_side_px: int | None = None

    def __post_init__(self) -> None:
        if self.base_channels < 1 or self.levels < 1 or self.num_classes < 2:
            raise ValueError(f"a U-Net needs base_channels >= 1, levels >= 1 and at least 2 "
                             f"classes, got {self}")
        if self.stem_stride not in (1, 2):
            raise ValueError(f"stem_stride must be 1 or 2, got {self.stem_stride}")
        if self.working_long_side_px is not None and self.working_long_side_px < 16:
            raise ValueError(f"working_long_side_px must be >= 16 or None, got "
                             f"{self.working_long_side_px}")


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
        c_first = 3
        if config.stem_stride == 2:
            c_first = widths[0]
            self.stem = nn.Sequential(
                nn.Conv2d(3, c_first, 3, stride=2, padding=1, bias=False),
                nn.BatchNorm2d(c_first), nn.ReLU(inplace=True))
        self.down = nn.ModuleList(
            _double_conv(c_in, c_out) for c_in, c_out in zip([c_first, *widths[:-1]], widths))
        self.up = nn.ModuleList(
            _double_conv(widths[k + 1] + widths[k], widths[k])
            for k in reversed(range(config.levels - 1)))
        self.head = nn.Conv2d(widths[0], config.num_classes, 1)

    def forward(self, rgb: Tensor) -> Tensor:
        if rgb.ndim != 4 or rgb.shape[1] != 3:
            raise ValueError(f"UNet takes (B, 3, H, W) RGB, got shape {tuple(rgb.shape)}")
        h, w = rgb.shape[-2:]
        multiple = 2 ** (self.config.levels - 1) * self.config.stem_stride
        pad_h, pad_w = -h % multiple, -w % multiple
        x = (rgb - _INPUT_MEAN) * _INPUT_SCALE
        if pad_h or pad_w:
            x = F.pad(x, (0, pad_w, 0, pad_h), mode="replicate")
        padded = x.shape[-2:]
        if self.config.stem_stride == 2:
            x = self.stem(x)
        skips = []
        for k, stage in enumerate(self.down):
            if k > 0:
                x = F.max_pool2d(x, 2)
            x = stage(x)
            skips.append(x)
        for stage, skip in zip(self.up, reversed(skips[:-1])):
            x = F.interpolate(x, size=skip.shape[-2:], mode="bilinear", align_corners=False)
            x = stage(torch.cat([x, skip], dim=1))
        logits = self.head(x)
        if self.config.stem_stride == 2:
            logits = F.interpolate(logits, size=padded, mode="bilinear", align_corners=False)
        return logits[..., :h, :w]
