"""Shading pieces: value noise, environment map, per-building look, texture coordinates."""

import numpy as np
import pytest

from dataset.rendering.shading import (
    RgbConfig,
    environment_radiance,
    sample_look,
    surface_coords,
    value_noise,
)


def test_value_noise_is_smooth_bounded_and_seeded():
    rng = np.random.default_rng(0)
    x, y = rng.uniform(-50, 50, (2, 5000))
    n = value_noise(x, y, seed=3)
    assert n.min() >= 0 and n.max() <= 1 and n.std() > 0.1
    # Continuous: a step of 1e-4 lattice units changes it by at most ~1.5e-4 (|slope| <= 1.5).
    assert np.abs(value_noise(x + 1e-4, y, seed=3) - n).max() < 2e-4
    np.testing.assert_array_equal(value_noise(x, y, seed=3), n)
    assert np.abs(value_noise(x, y, seed=4) - n).mean() > 0.1


def test_environment_sky_up_ground_down_sun_brightest():
    look = sample_look(2)
    up = environment_radiance(np.array([[0.0, 0.0, 1.0]]), look)[0]
    down = environment_radiance(np.array([[0.0, 0.0, -1.0]]), look)[0]
    assert up[2] > up[0]  # blue sky
    assert not np.allclose(up, down)
    sun = environment_radiance(look.sun_dir[None], look)[0]
    no_disc = environment_radiance(look.sun_dir[None], look, sun_disc=False)[0]
    assert sun.sum() > 10 * no_disc.sum() > 0
    rng = np.random.default_rng(1)
    d = rng.normal(size=(1000, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    radiance = environment_radiance(d, look)
    assert radiance.shape == (1000, 3) and (radiance >= 0).all() and np.isfinite(radiance).all()


def test_look_is_seeded_and_honours_the_config():
    a, b = sample_look(7), sample_look(7)
    np.testing.assert_array_equal(a.sun_dir, b.sun_dir)
    np.testing.assert_array_equal(a.wall_rgb, b.wall_rgb)
    assert not np.allclose(sample_look(8).sun_dir, a.sun_dir)
    np.testing.assert_allclose(np.linalg.norm(a.sun_dir), 1.0)
    config = RgbConfig(wall_material="brick", sun_elevation_deg=(30.0, 30.0))
    for seed in range(5):
        look = sample_look(seed, config)
        assert look.wall_material == "brick"
        assert np.degrees(np.arcsin(look.sun_dir[2])) == pytest.approx(30.0)


def test_surface_coords_on_walls_and_roofs():
    points = np.array([[3.0, -6.0, 2.0], [3.0, 4.0, 9.0]])
    normals = np.array([[0.0, -1.0, 0.0], [0.0, 0.0, 1.0]])
    s, v = surface_coords(points, normals)
    # Wall facing -y: along the wall is +x (right for a viewer facing it), v is height.
    np.testing.assert_allclose([s[0], v[0]], [3.0, 2.0])
    np.testing.assert_allclose([s[1], v[1]], [3.0, 4.0])  # roof: world x, y


def test_bad_rgb_configs_are_refused():
    with pytest.raises(ValueError, match="sun_elevation_deg"):
        RgbConfig(sun_elevation_deg=(70.0, 20.0))
    with pytest.raises(ValueError, match="glass_reflectance"):
        RgbConfig(glass_reflectance=2.0)
