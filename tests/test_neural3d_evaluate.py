"""Evaluation figures on a field whose answer is known: everything is sky."""

import numpy as np
import torch

from neural3d.config import preset_config
from neural3d.data import Pixels
from neural3d.evaluate import evaluate
from neural3d.fields import SemanticSDF


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
