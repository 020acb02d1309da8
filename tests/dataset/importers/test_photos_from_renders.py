"""dataset.importers.photos end to end on the project's own renders: a procedural building
rendered in the photo look (RgbConfig(look="photo")), stripped to its RGB images
(dataset.importers.photos.stripped_renders), posed by structure from motion with one known
distance, and compared with the true cameras (issue 47: >= 90 % of the views posed, scale
within 2 %). bench/photos_from_renders.py runs the same at 1024 px on more buildings
(docs/measurements/photo-look.md)."""

import numpy as np
import pytest

from dataset.generate import generate_preset
from dataset.importers.photos.stripped_renders import pose_stripped_renders
from dataset.rendering.orbit_views import OrbitConfig
from dataset.rendering.shading import RgbConfig
from dataset.scenes.scene_writer import GenerateConfig

MIN_POSED_FRACTION = 0.9
SCALE_TOLERANCE = 0.02
"""The issue's bar for the stripped renders."""
CONFIG = GenerateConfig(resolution=512, views=32, ideal=False, multi=False,
                        orbit=OrbitConfig(elevation_deg=(15.0, 35.0)),
                        rgb=RgbConfig(look="photo"))
"""A small capture: 32 orbit views of 512 px, 15-35 degrees above the building's centre (a
drone circling it). With 24 views, two runs of the same renders posed 23 and 14 of them:
COLMAP's multi-threaded mapping is not repeatable, and 24 views of 512 px are too few to
leave a margin."""
# Measured (2026-11-29, pycolmap 4.2.1, twice): 32 of 32 posed, scale 0.03 / 0.04 % off,
# median rotation 0.17 degrees, median position 0.055 m (orbit of about 30 m); the test
# takes about 40 s on 2 cores shared with a background job. Tolerances leave room for
# another machine.
ROTATION_TOLERANCE_DEG = 1.0
POSITION_TOLERANCE_M = 0.5


@pytest.mark.slow
def test_photo_look_renders_are_posed_from_the_images_alone(tmp_path):
    scene, = generate_preset("tiny", tmp_path / "scenes", CONFIG, buildings=["tiny_l_shaped"],
                             progress=False)
    run = pose_stripped_renders(scene, tmp_path / "work", ("train", "eval"))
    assert run.failure == ""
    assert run.posed_fraction >= MIN_POSED_FRACTION, run.posed
    assert run.errors.scale_error < SCALE_TOLERANCE
    assert np.median(run.errors.rotation_deg) < ROTATION_TOLERANCE_DEG
    assert np.median(run.errors.position_m) < POSITION_TOLERANCE_M


@pytest.mark.slow
def test_shuffled_and_renamed_photos_are_posed_as_well(tmp_path):
    """A user's folder: the same capture under names in random order (IMG_<n>.jpg), so
    neither the names nor COLMAP's image order say where a photo was taken; the pairs
    preemptive matching keeps (the default) depend on the features alone."""
    scene, = generate_preset("tiny", tmp_path / "scenes", CONFIG, buildings=["tiny_l_shaped"],
                             progress=False)
    run = pose_stripped_renders(scene, tmp_path / "work", ("train", "eval"), shuffle_seed=7)
    assert run.failure == ""
    assert run.posed_fraction >= MIN_POSED_FRACTION, run.posed
    assert run.errors.scale_error < SCALE_TOLERANCE
    assert np.median(run.errors.rotation_deg) < ROTATION_TOLERANCE_DEG
