"""The U-Net: logits of the input's size for any image size, refused shapes, one definition."""

import pytest
import torch

from envelope.classes import NUM_CLASSES
from segment.network import UNet, UNetConfig


@pytest.mark.parametrize("size", [(1, 1), (37, 53), (64, 64), (96, 130)])
def test_logits_have_the_input_size_whatever_it_is(size):
    model = UNet(UNetConfig(base_channels=4, levels=4)).eval()
    with torch.no_grad():
        out = model(torch.rand(2, 3, *size))
    assert out.shape == (2, NUM_CLASSES, *size)
    assert torch.isfinite(out).all()


def test_padding_does_not_leak_into_the_pixels_it_keeps():
    # A 64 x 64 image (a multiple of 8) needs no padding; its top-left 60 x 60 crop is padded
    # to 64 by edge values. Far from the padded border both see the same receptive field.
    torch.manual_seed(0)
    model = UNet(UNetConfig(base_channels=4, levels=2)).eval()
    image = torch.rand(1, 3, 64, 64)
    with torch.no_grad():
        full, crop = model(image), model(image[..., :60, :60])
    assert torch.allclose(full[..., :50, :50], crop[..., :50, :50], atol=1e-5)


def test_bad_inputs_and_configs_are_refused():
    with pytest.raises(ValueError, match=r"\(B, 3, H, W\)"):
        UNet(UNetConfig(base_channels=4, levels=2))(torch.rand(3, 8, 8))
    with pytest.raises(ValueError, match="at least 2 classes"):
        UNetConfig(num_classes=1)
    with pytest.raises(ValueError, match="levels"):
        UNetConfig(levels=0)


@pytest.mark.parametrize("size", [(1, 1), (37, 53), (64, 64)])
def test_a_strided_stem_still_gives_logits_of_the_input_size(size):
    model = UNet(UNetConfig(base_channels=4, levels=3, stem_stride=2)).eval()
    with torch.no_grad():
        out = model(torch.rand(1, 3, *size))
    assert out.shape == (1, NUM_CLASSES, *size)
    assert torch.isfinite(out).all()


def test_stem_and_working_scale_are_checked():
    with pytest.raises(ValueError, match="stem_stride must be 1 or 2"):
        UNetConfig(stem_stride=4)
    with pytest.raises(ValueError, match="working_long_side_px"):
        UNetConfig(working_long_side_px=8)
