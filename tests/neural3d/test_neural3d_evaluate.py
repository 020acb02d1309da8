"""Evaluation figures on a field whose answer is known: everything is sky."""

import numpy as np
import torch

from neural3d.config import preset_config
from neural3d.field.fields import SemanticSDF
from neural3d.training.data import Pixels
from neural3d.training.evaluate import eval_pixel_subset, evaluate


def test_all_sky_pixels():
    config = preset_config("tiny")
    torch.manual_seed(0)
    field = SemanticSDF(config.model, 3, np.full(3, -1.0), np.full(3, 1.0))
    n = 8
    dirs = torch.tensor([[0.0, 0.0, -1.0]]).repeat(n, 1)
    origins = torch.tensor([[0.0, 5.0, 3.0]]).repeat(n, 1)  # rays pass beside the box
    with torch.no_grad():
        sky = field.background_rgb(dirs)
    pixels = Pixels(origins=origins, dirs=dirs, rgb=sky, labels=torch.zeros(n, dtype=torch.long),
                    depth_t=None, shapes=((2, 4),))
    lo, hi = torch.full((3,), -1.0), torch.full((3,), 1.0)
    figures = evaluate(field, pixels, lo, hi, config, step=0, background_class=0)
    assert figures["psnr"] > 60  # exact colours: PSNR capped by the 1e-10 MSE floor at 100
    assert figures["semantic_accuracy"] == 1.0 and figures["mask_iou"] == 1.0


def test_eval_pixel_subset_draws_the_same_pixels_of_every_frame():
    shapes = ((4, 5), (2, 3))
    n = 26
    labels = torch.arange(n)
    pixels = Pixels(origins=torch.zeros(n, 3), dirs=torch.zeros(n, 3), rgb=torch.zeros(n, 3),
                    labels=labels, depth_t=None, shapes=shapes)
    a = eval_pixel_subset(pixels, 4, seed=0)
    b = eval_pixel_subset(pixels, 4, seed=0)
    assert torch.equal(a.labels, b.labels) and a.shapes == ((1, 4), (1, 4))
    assert (a.labels[:4] < 20).all() and (a.labels[4:] >= 20).all()  # 4 from each frame
    assert len(set(a.labels.tolist())) == 8
    assert eval_pixel_subset(pixels, 0, seed=0) is pixels  # 0: every pixel
    assert len(eval_pixel_subset(pixels, 100, seed=0)) == n  # capped at the frame size
