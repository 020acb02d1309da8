"""The committed weights on a real photo (tests/fixtures/photo_building: a camera's photo of
a building, MIT, with no labels): each segments it at its own size, and reads its sky as
background. No window IoU is asserted: nobody labelled the photo's windows."""

from pathlib import Path

import numpy as np
import pytest

from envelope.classes import NUM_CLASSES, SemanticClass
from envelope.photo_io import read_photo_rgb
from segment.segmenter import resolve_segmenter, segment_rgb
from segment.weights import BUILT_IN_WEIGHTS

PHOTO = Path(__file__).parents[1] / "fixtures" / "photo_building" / "palace-of-culture-400px.jpg"
SKY_ROWS = 200  # rows 0-199 of 600: sky, but for the spire's tip (under 1 % of them)
MIN_SKY_BACKGROUND = 0.95


@pytest.mark.parametrize("weights", sorted(BUILT_IN_WEIGHTS))
def test_a_real_photo_segments_at_its_size_with_its_sky_as_background(weights: str) -> None:
    rgb = read_photo_rgb(PHOTO)
    assert rgb.shape == (600, 400, 3)
    labels = segment_rgb(resolve_segmenter(weights, threads=1), rgb)
    assert labels.shape == (600, 400) and labels.dtype == np.uint8
    assert labels.max() < NUM_CLASSES
    sky = labels[:SKY_ROWS]
    assert (sky == SemanticClass.BACKGROUND).mean() >= MIN_SKY_BACKGROUND
    # The building's half is not read as background alone: wall is found there.
    assert (labels[SKY_ROWS:] == SemanticClass.WALL).mean() > 0.2
