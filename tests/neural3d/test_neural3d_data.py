"""Scene loading: rays in the normalised frame, image scaling, validation messages."""

import numpy as np
import pytest
import torch
from neural3d_scene import write_ring_scene

from envelope.camera import unproject_depth_to_world
from envelope.scenes.scene import read_scene
from neural3d.training.data import (
    background_class,
    frames_to_pixels,
    load_frames,
    scene_normalisation,
)


@pytest.fixture(scope="module")
def scene(box_building, tmp_path_factory):
    return read_scene(write_ring_scene(box_building, tmp_path_factory.mktemp("d") / "s",
                                       size_px=24, n_train=8, n_eval=2))


@pytest.mark.slow
def test_rays_reach_the_depth_points(scene):
    frames = load_frames(scene, "train", with_depth=True)
    norm = scene_normalisation(frames, background_class(scene), margin=0.1)
    px = frames_to_pixels(frames, norm, torch.device("cpu"))
    f = frames[0]
    h, w = f.labels.shape
    assert len(px) == 8 * h * w and px.shapes[0] == (h, w)
    assert torch.allclose(px.dirs.norm(dim=1), torch.ones(len(px)), atol=1e-5)
    # origin + t * dir (normalised) must be the unprojected depth point (world metres).
    uv = np.stack(np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5), -1).reshape(-1, 2)
    world = unproject_depth_to_world(uv, f.depth_z_m.reshape(-1), f.intrinsics,
                                     f.world_from_camera)
    hit = f.depth_z_m.reshape(-1) > 0
    t = px.depth_t[: h * w]
    assert torch.isnan(t[~hit]).all()
    pts = px.origins[: h * w] + px.dirs[: h * w] * t[:, None]
    back = norm.world_from_unit(pts.double())[hit].numpy()
    assert np.abs(back - world[hit]).max() < 1e-3 * norm.scale_m


def test_image_scale_resizes_images_and_intrinsics(scene):
    half = load_frames(scene, "train", image_scale=0.5)
    assert half[0].rgb.shape == (12, 12, 3) and half[0].labels.shape == (12, 12)
    assert half[0].intrinsics.width == 12


@pytest.mark.slow
def test_normalisation_box_contains_the_building(scene):
    frames = load_frames(scene, "train")
    norm = scene_normalisation(frames, 0, margin=0.0)
    assert np.all(np.asarray(norm.box_min_m) <= [-10.0, -6.0, 0.0])
    assert np.all(np.asarray(norm.box_max_m) >= [10.0, 6.0, 9.0])


def test_missing_split_and_class_errors(scene):
    with pytest.raises(ValueError, match="no 'multi' frames"):
        load_frames(scene, "multi")
    from dataclasses import replace

    with pytest.raises(ValueError, match="neither the project's"):
        load_frames(replace(scene, semantic_classes=("sky", "wall")), "train")
    assert background_class(scene) == 0
