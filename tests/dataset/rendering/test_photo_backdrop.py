"""The photo look's backdrop (a belt of trees far off): where rays meet it, in closed form,
and fixed to the world."""

import numpy as np

from dataset.rendering.photo_backdrop import (
    BACKDROP_GAP_M,
    TREE_HEIGHT_M,
    backdrop_hits,
    backdrop_radiance,
    backdrop_radius_m,
)
from dataset.rendering.shading import RgbConfig, sample_look

BOUNDS = np.array([[-10.0, -6.0, 0.0], [10.0, 6.0, 9.0]])
RADIUS_M = 0.5 * np.hypot(20.0, 12.0) + BACKDROP_GAP_M
SEED = 5


def test_the_belt_stands_its_gap_outside_the_bounding_box():
    assert backdrop_radius_m(BOUNDS) == RADIUS_M
    assert backdrop_radius_m(BOUNDS + [100.0, -50.0, 3.0]) == RADIUS_M  # centred on the box


def test_where_rays_from_the_centre_meet_the_belt():
    eye = np.array([0.0, 0.0, 2.5])
    low = TREE_HEIGHT_M[0] - eye[2]  # rises to the tree line's lowest top at the belt
    dirs = np.array([
        [1.0, 0.0, 0.0],                       # level, along +x: arc 0, at eye height
        [0.0, 1.0, 0.0],                       # level, along +y: a quarter round
        [1.0, 0.0, 0.9 * low / RADIUS_M],      # up, below every tree top
        [1.0, 0.0, 2.0 * TREE_HEIGHT_M[1] / RADIUS_M],  # up, above every tree top: sky
        [0.0, 0.0, 1.0],                       # straight up: never
        [1.0, 0.0, -0.5],                      # down: the ground 5 m off, before the belt
    ])
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    hit, t, arc, z = backdrop_hits(np.tile(eye, (len(dirs), 1)), dirs, BOUNDS, SEED)
    np.testing.assert_array_equal(hit, [True, True, True, False, False, False])
    np.testing.assert_allclose(t[:2], RADIUS_M, rtol=1e-12)
    np.testing.assert_allclose(arc[:2], [0.0, RADIUS_M * np.pi / 2], atol=1e-9)
    np.testing.assert_allclose(z[:3], [2.5, 2.5, 2.5 + 0.9 * low], rtol=1e-12)


def test_cameras_outside_the_belt_do_not_see_it():
    eye = np.array([[RADIUS_M + 1.0, 0.0, 2.5]])
    hit, t, _, _ = backdrop_hits(eye, np.array([[-1.0, 0.0, 0.0]]), BOUNDS, SEED)
    assert not hit[0] and np.isnan(t[0])


def test_a_point_of_the_belt_looks_the_same_from_mirrored_cameras():
    # Two cameras mirrored about the belt's inward normal at a point, at the same distance:
    # the same footprint and incidence, so a texture fixed to the world gives the same colour.
    look = sample_look(SEED, RgbConfig(look="photo"))
    angle = 0.7
    target = np.array([RADIUS_M * np.cos(angle), RADIUS_M * np.sin(angle), 3.0])
    inward = -np.array([np.cos(angle), np.sin(angle), 0.0])
    side = np.array([-np.sin(angle), np.cos(angle), 0.0])
    origins = np.stack([target + 25.0 * (0.8 * inward + s * 0.6 * side) + [0, 0, -0.5]
                        for s in (1, -1)])
    dirs = target - origins
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    hit, radiance = backdrop_radiance(origins, dirs, BOUNDS, look, 1e-3)
    assert hit.all()
    np.testing.assert_allclose(radiance[0], radiance[1], rtol=1e-9)
    # ...and a point a metre round the belt looks different.
    other = np.array([RADIUS_M * np.cos(angle + 1.0 / RADIUS_M),
                      RADIUS_M * np.sin(angle + 1.0 / RADIUS_M), 3.0]) - origins[:1]
    _, far = backdrop_radiance(origins[:1], other / np.linalg.norm(other), BOUNDS, look, 1e-3)
    assert np.abs(far[0] - radiance[0]).max() > 1e-3 * radiance[0].max()
