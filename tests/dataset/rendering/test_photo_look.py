"""The photo look (RgbConfig(look="photo")): RGB only, deterministic, fixed to the world, off by
default."""

import numpy as np
import pytest

from dataset.rendering.photo_look import ground_albedo, photo_materials, plane_offset_m
from dataset.rendering.render import Raycaster, RgbConfig, render_view
from dataset.rendering.shading import sample_look, shade
from dataset.scenes.scene_writer import GenerateConfig, generator_record
from envelope.camera import Intrinsics, look_at
from envelope.classes import SemanticClass

K = Intrinsics.from_fov(64, 48, 60.0)
POSE = look_at([-23.3, -31.7, 6.2], [0.7, 0.4, 3.9])  # the box's -y and -x walls and ground
PHOTO = RgbConfig(look="photo")
WALL_POINT_M = np.array([2.3, -6.0, 1.1])
"""A point on the box's -y wall (between two ground-floor windows)."""


@pytest.fixture(scope="module")
def box_raycaster(box_building):
    return Raycaster(box_building.mesh)


def test_the_look_changes_the_rgb_alone(box_raycaster):
    plain_truth, plain_rgb = render_view(box_raycaster, K, POSE, seed=5)
    photo_truth, photo_rgb = render_view(box_raycaster, K, POSE, seed=5, config=PHOTO)
    for name in ("depth_z_m", "normals_world", "labels", "facade_ids"):
        np.testing.assert_array_equal(getattr(photo_truth, name), getattr(plain_truth, name))
    # Walls, roof and ground all change: most pixels differ.
    assert (np.abs(photo_rgb.astype(int) - plain_rgb).sum(axis=2) > 6).mean() > 0.5


def test_the_look_is_deterministic(box_raycaster):
    _, a = render_view(box_raycaster, K, POSE, seed=5, config=PHOTO, supersampling=2)
    _, b = render_view(box_raycaster, K, POSE, seed=5, config=PHOTO, supersampling=2)
    np.testing.assert_array_equal(a, b)


def _radiance_from(raycaster, origins_m, target_m, seed=5):
    dirs = target_m - origins_m
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    face, t = raycaster.first_hit(origins_m, dirs)
    return face, shade(raycaster, origins_m=origins_m, dirs=dirs, face=face, t=t, config=PHOTO,
                       seed=seed, pixel_angle_rad=1e-3)


@pytest.mark.parametrize("target", [WALL_POINT_M, np.array([3.1, -14.0, 0.0])],
                         ids=["wall", "ground"])
def test_a_point_looks_the_same_from_mirrored_cameras(box_raycaster, target):
    # Two cameras mirrored about the surface normal through the point, at the same distance:
    # same footprint and incidence, so a texture fixed to the world gives the same radiance.
    normal = np.array([0.0, -1.0, 0.0]) if target[2] > 0 else np.array([0.0, 0.0, 1.0])
    side = np.array([1.0, 0.0, 0.0])
    origins = np.stack([target + 12.0 * (0.8 * normal + s * 0.6 * side) for s in (1, -1)])
    face, radiance = _radiance_from(box_raycaster, origins, np.stack([target, target]))
    if target[2] > 0:
        assert (box_raycaster.mesh.face_label[face] == SemanticClass.WALL).all()
    else:
        assert (face < 0).all()  # the ground is no geometry: the pixels stay background
    np.testing.assert_allclose(radiance[0], radiance[1], rtol=1e-9)
    # ...and another point nearby looks different (the texture is not flat there).
    _, other = _radiance_from(box_raycaster, origins[:1], target[None] + [0.37, 0.0, 0.0])
    assert np.abs(other[0] - radiance[0]).max() > 1e-3 * radiance[0].max()


def test_ground_zones_by_distance_from_the_building():
    look = sample_look(5)
    materials = photo_materials(look)
    bounds = np.array([[-10.0, -6.0, 0.0], [10.0, 6.0, 9.0]])
    # On the paving 1 m out, on the kerb, on the road's edge line, far out in the grass:
    x = np.array([0.0, 0.0, 0.0, 0.0])
    y = -6.0 - np.array([1.0, 2.65, 2.8 + 0.375, 40.0])
    albedo = ground_albedo(x, y, bounds, look, materials, np.full(4, 1e-3))
    assert albedo[2].min() > 0.4  # the white line
    assert albedo[2].mean() > albedo[3].mean() and albedo[1].mean() > albedo[0].mean() * 0.9


def test_the_look_is_off_by_default_and_recorded_when_on():
    assert RgbConfig().look == "plain"
    plain = generator_record(GenerateConfig(), seed=0)["config"]["rgb"]
    photo = generator_record(GenerateConfig(rgb=PHOTO), seed=0)["config"]["rgb"]
    assert "look" not in plain  # plain scenes record what they always did
    assert photo["look"] == "photo"
    with pytest.raises(ValueError, match="look must be 'plain' or 'photo'"):
        RgbConfig(look="glossy")


def test_walls_are_told_apart_by_their_texture_offset():
    # Constant on a plane (any point of the -y wall), different on every other wall.
    wall = np.array([[x, -6.0, z] for x in (-8.0, 0.0, 7.5) for z in (0.5, 8.0)])
    normals = np.tile([0.0, -1.0, 0.0], (len(wall), 1))
    offsets = plane_offset_m(wall, normals)
    np.testing.assert_allclose(offsets, offsets[0], atol=1e-9)
    others = plane_offset_m(np.array([[0.0, 6.0, 1.0], [10.0, 0.0, 1.0], [-10.0, 0.0, 1.0],
                                      [0.0, -9.0, 1.0]]),
                            np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0],
                                      [0.0, -1.0, 0.0]]))
    assert np.abs(others - offsets[0]).min() > 10.0
