"""A network's working scale: images scaled to its long side and scores scaled back, and
training frames read once at that scale."""

from types import SimpleNamespace

import numpy as np
import pytest
import torch

from envelope.classes import NUM_CLASSES
from segment.network import UNet, UNetConfig
from segment.segmenter import predict_labels, predict_logits, scale_to_long_side
from segment.training_data import preload


@pytest.mark.parametrize(("shape", "long_side", "expected"), [
    ((300, 400, 3), 512, (384, 512, 3)),   # enlarged: 400 -> 512, 300 * 1.28 = 384
    ((1024, 683, 3), 512, (512, 342, 3)),  # shrunk, portrait: 683 / 2 = 341.5 -> 342 (to even)
    ((7, 3), 14, (14, 6)),                 # labels: (H, W)
])
def test_the_long_side_gets_the_working_size_and_the_aspect_is_kept(shape, long_side, expected):
    image = np.random.default_rng(0).integers(0, 6, shape).astype(np.uint8)
    out = scale_to_long_side(image, long_side, labels=len(shape) == 2)
    assert out.shape == expected and out.dtype == np.uint8


def test_labels_keep_their_ids_and_nothing_changes_without_a_working_size():
    labels = np.array([[0, 2], [5, 1]], np.uint8)
    out = scale_to_long_side(labels, 8, labels=True)
    # Nearest neighbour: each id becomes a 4 x 4 block, no id in between appears.
    assert np.array_equal(out, np.kron(labels, np.ones((4, 4), np.uint8)))
    assert scale_to_long_side(labels, None) is labels
    assert scale_to_long_side(labels, 2) is labels


def test_scores_come_back_at_the_photo_size_and_match_the_scaled_image():
    torch.manual_seed(0)
    config = UNetConfig(base_channels=4, levels=3, stem_stride=2, working_long_side_px=32)
    model = UNet(config).eval()
    rgb = np.random.default_rng(1).integers(0, 256, (45, 90, 3)).astype(np.uint8)
    logits = predict_logits(model, rgb, threads=1)
    assert logits.shape == (NUM_CLASSES, 45, 90)
    assert predict_labels(model, rgb, threads=1).shape == (45, 90)
    # The same network without a working size, given the image already scaled to 32 x 16:
    # its scores, scaled back, are what the working-size path returns.
    plain = UNet(UNetConfig(base_channels=4, levels=3, stem_stride=2)).eval()
    plain.load_state_dict(model.state_dict())
    small = predict_logits(plain, scale_to_long_side(rgb, 32), threads=1)
    assert small.shape == (NUM_CLASSES, 16, 32)
    back = torch.nn.functional.interpolate(small[None], size=(45, 90), mode="bilinear",
                                           align_corners=False)[0]
    assert torch.allclose(back, logits, atol=1e-5)


def test_preloading_keeps_evenly_spaced_frames_at_the_working_scale():
    rng = np.random.default_rng(2)
    frames = {k: (rng.integers(0, 256, (100, 200, 3)).astype(np.uint8),
                  rng.integers(0, 6, (100, 200)).astype(np.uint8)) for k in "abcdef"}
    source = SimpleNamespace(name="set/train", frames=tuple("abcdef"), record={"set": "x"},
                             rgb_and_labels=frames.__getitem__)
    [kept] = preload([source], 50, frames_per_source=3, progress=False)
    assert kept.name == "set/train" and kept.frames == (0, 1, 2)
    assert kept.record == {"set": "x", "frames_read": 3}
    rgb, labels = kept.rgb_and_labels(1)
    assert rgb.shape == (25, 50, 3) and labels.shape == (25, 50)
    # The three kept are a, c and f (evenly spaced); the second is c, scaled.
    assert np.array_equal(labels, scale_to_long_side(frames["c"][1], 50, labels=True))
    assert np.array_equal(rgb, scale_to_long_side(frames["c"][0], 50))
    [everything] = preload([source], None, progress=False)
    assert everything.frames == tuple(range(6))
    assert everything.rgb_and_labels(5)[0] is frames["f"][0]
