"""Visual-hull scene box from silhouettes of an analytic box seen by a ring of cameras."""

import numpy as np
import pytest

from envelope.camera import Intrinsics, look_at, project_world_to_image
from neural3d.training.scene_box import visual_hull_box_m

LO, HI = np.array([-4.0, -2.0, 0.0]), np.array([4.0, 2.0, 6.0])


def views(n=16, size=64):
    k = Intrinsics.from_fov(size, size, 50)
    corners = np.array([[x, y, z] for x in (LO[0], HI[0]) for y in (LO[1], HI[1])
                        for z in (LO[2], HI[2])])
    poses, masks = [], []
    for i in range(n):
        a, e = 2 * np.pi * i / n, np.deg2rad(15 + 40 * (i % 3) / 2)
        eye = np.array([np.cos(a) * np.cos(e), np.sin(a) * np.cos(e), np.sin(e)]) * 20
        pose = look_at(eye, (LO + HI) / 2)
        # The box's silhouette is the convex hull of its projected corners.
        import cv2

        uv, _ = project_world_to_image(corners, k, pose)
        mask = np.zeros((size, size), np.uint8)
        cv2.fillConvexPoly(mask, cv2.convexHull((uv * 16).astype(np.int32)), 1, shift=4)
        poses.append(pose)
        masks.append(mask.astype(bool))
    return [k] * n, poses, masks


@pytest.mark.slow
def test_hull_box_is_tight_around_the_box():
    ks, poses, masks = views()
    lo, hi = visual_hull_box_m(ks, poses, masks, margin=0.0)
    assert np.all(lo <= LO + 1e-9) and np.all(hi >= HI - 1e-9)
    # Carving leaves at most ~one coarse voxel plus the silhouettes' slack (measured < 1.5 m).
    assert np.all(lo >= LO - 1.5) and np.all(hi <= HI + 2.0), (lo, hi)


@pytest.mark.slow
def test_margin_grows_the_box():
    ks, poses, masks = views()
    lo0, hi0 = visual_hull_box_m(ks, poses, masks, margin=0.0)
    lo, hi = visual_hull_box_m(ks, poses, masks, margin=0.1)
    assert np.allclose(lo0 - lo, 0.1 * np.max(hi0 - lo0))


def test_bad_inputs():
    ks, poses, masks = views(n=4)
    with pytest.raises(ValueError, match="one intrinsics, pose and mask"):
        visual_hull_box_m(ks, poses[:3], masks)
    with pytest.raises(ValueError, match="no foreground"):
        visual_hull_box_m(ks, poses, [np.zeros_like(m) for m in masks])
    with pytest.raises(ValueError, match="does not match image size"):
        visual_hull_box_m(ks, poses, [m[:10] for m in masks])
