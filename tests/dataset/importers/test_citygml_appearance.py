"""CityGML appearance in the RGB render: textures (``ParameterizedTexture``) and material
colours (``X3DMaterial``); labels and depth never change with them."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest
from citygml_boxes import Box, write_boxes
from PIL import Image

from dataset.importers.citygml.appearance import face_appearance
from dataset.importers.citygml.convert import import_citygml
from dataset.importers.citygml.preset import LOD3_DIR
from dataset.importers.citygml.read import read_citygml
from dataset.rendering.render import render_view
from dataset.rendering.textures import SRGB_GAMMA, prepare_textures, texture_albedo
from envelope.appearance import SurfaceAppearance
from envelope.camera import Intrinsics, look_at
from envelope.classes import SemanticClass


def test_texture_coordinates_of_a_real_file_are_reproduced():
    """Every textured polygon of 4018133 (roof tiles, doors, balcony slabs): the affine map
    gives back the file's texture coordinates at each ring corner (to 0.01 of a tile)."""
    model = read_citygml(LOD3_DIR / "4018133" / "4018133.xml.xz")
    (building,) = model.buildings
    checked = 0
    for p in building.polygons:
        look = model.looks.get(p.polygon_id)
        if look is None or look.image_uri is None:
            continue
        a = face_appearance([look], [(p.ring_ids, p.rings_m)], [p.reversed], [1],
                            np.zeros(3), model.path.parent, Counter())
        assert a is not None and a.face_material.tolist() == [0]
        for rid, ring in zip(p.ring_ids, p.rings_m):
            uv = np.column_stack([ring, np.ones(len(ring))]) @ a.uv_from_world[0].T
            assert uv == pytest.approx(look.ring_uv[rid], abs=0.01)
        checked += 1
    assert checked == 26


def test_texture_albedo_at_texel_centres_and_far_away():
    """A 4 x 2 texture: sampled close up at its texel centres it gives each texel's linear
    value; seen from far (a pixel covers the whole tile) it gives the texture's mean."""
    image = (np.arange(24, dtype=np.uint8).reshape(2, 4, 3) * 10)
    # One face in the plane z = 0 with u = x, v = y (one tile per metre).
    uv_map = np.array([[[1.0, 0, 0, 0], [0, 1.0, 0, 0]]])
    textures = prepare_textures(SurfaceAppearance(np.array([0]), uv_map, (image,)))
    rows, cols = np.mgrid[0:2, 0:4]
    points = np.column_stack([(cols.ravel() + 0.5) / 4, 1 - (rows.ravel() + 0.5) / 2,
                              np.zeros(8)])
    has, albedo = texture_albedo(textures, np.zeros(8, int), points, np.full(8, 1e-4))
    linear = (image.reshape(-1, 3) / 255.0) ** SRGB_GAMMA
    assert has.all() and albedo == pytest.approx(linear, abs=1e-6)
    has, albedo = texture_albedo(textures, np.zeros(8, int), points, np.full(8, 10.0))
    assert albedo == pytest.approx(np.broadcast_to(linear.mean(axis=0), (8, 3)), abs=1e-6)


def test_a_textured_window_and_a_coloured_wall_render_their_colours(tmp_path):
    """A window textured left half red, right half green, on a wall whose material is blue:
    seen head on, the window's left pixels are red, its right pixels green, the wall blue;
    the label and depth images are those of the same view without appearance."""
    tex = np.zeros((8, 8, 3), np.uint8)
    tex[:, :4] = (220, 30, 30)
    tex[:, 4:] = (30, 200, 30)
    (tmp_path / "textures").mkdir()
    Image.fromarray(tex).save(tmp_path / "textures" / "glass.png")
    box = Box("T", (0, 10), (0, 10), 8, windows=((2, 1, 8, 6),), wall_rgb=(0.1, 0.2, 0.9),
              window_texture="textures/glass.png")
    (b,) = import_citygml(write_boxes(tmp_path / "t.gml", [box]))
    assert b.appearance is not None and (b.appearance.face_material >= 0).any()
    k = Intrinsics.from_fov(64, 64, 60.0)
    pose = look_at(np.array([0.0, -18.0, 3.5]), np.array([0.0, -5.0, 3.5]))
    gt, rgb = render_view(b.mesh, k, pose, textures=prepare_textures(b.appearance), seed=3)
    plain_gt, plain = render_view(b.mesh, k, pose, seed=3)
    for name in ("labels", "depth_z_m", "facade_ids", "normals_world"):
        assert np.array_equal(getattr(gt, name), getattr(plain_gt, name))
    rgb = rgb.astype(int)
    window = gt.labels == SemanticClass.WINDOW
    cols = np.nonzero(window.any(axis=0))[0]
    mid = (cols.min() + cols.max()) / 2
    # Away from the tile's edges, where bilinear filtering blends the tiled neighbour in.
    x = np.arange(64)[None, :]
    left = window & (x > cols.min() + 2) & (x < mid - 2)
    right = window & (x > mid + 2) & (x < cols.max() - 2)
    wall = gt.labels == SemanticClass.WALL
    assert left.sum() > 50 and right.sum() > 50 and wall.sum() > 200
    assert np.all(rgb[left, 0] > 2 * rgb[left, 1])
    assert np.all(rgb[right, 1] > 2 * rgb[right, 0])
    assert np.median(rgb[wall, 2]) > 2 * np.median(rgb[wall, 0])
    # Without appearance the window is the procedural glass, not red or green.
    assert not np.all(plain.astype(int)[left, 0] > 2 * plain.astype(int)[left, 1])
