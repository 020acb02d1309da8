"""neural3d.extraction.meshing: marching cubes of analytic SDFs, vertex semantics and the semantic
PLY."""

import numpy as np
import pytest
import trimesh
from sdf_shapes import box_sdf

from envelope.mesh import triangle_areas_m2
from envelope.semantic_ply import read_semantic_ply, write_semantic_ply
from neural3d.extraction.meshing import (
    color_vertices,
    extract_mesh,
    grid_axes_m,
    label_vertices,
    remove_small_components,
    vertex_normals,
)

BOX_LO, BOX_HI = np.array([-3.0, -2.0, 0.0]), np.array([3.0, 2.0, 5.0])  # 6 x 4 x 5 m


def _box(p):
    return box_sdf(p, BOX_LO, BOX_HI)


def _sphere(centre, radius):
    return lambda p: np.linalg.norm(p - np.asarray(centre, float), axis=1) - radius


def _signed_volume_m3(v, f):
    t = v[f]
    return float(np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6.0)


def test_box_area_and_outward_volume():
    # a box whose faces fall between samples (on samples the mesh would be exact)
    v, f = extract_mesh(_box, [-4.013, -3.027, -1.031], [4, 3, 6], voxel_size_m=0.05)
    area = triangle_areas_m2(v[f]).sum()
    true_area = 2 * (6 * 4 + 6 * 5 + 4 * 5)
    # marching cubes cuts the box's edges, so the area can only fall short: 1 % is the spec
    assert 0.99 * true_area <= area <= true_area * (1 + 1e-9)
    # positive signed volume = faces wind counter-clockwise seen from outside
    assert _signed_volume_m3(v, f) == pytest.approx(120.0, rel=1e-3)


def test_sphere_normals_point_out():
    v, f = extract_mesh(_sphere([1, 2, 3], 2.0), [-2, -1, 0], [4, 5, 6], resolution=64)
    radial = (v - [1, 2, 3]) / np.linalg.norm(v - [1, 2, 3], axis=1, keepdims=True)
    cos = np.sum(vertex_normals(v, f) * radial, axis=1)
    assert cos.min() > 0.98
    assert triangle_areas_m2(v[f]).sum() == pytest.approx(4 * np.pi * 4, rel=0.01)


def test_chunking_does_not_change_the_mesh():
    args = (_sphere([0, 0, 0], 1.0), [-1.5] * 3, [1.5] * 3)
    v1, f1 = extract_mesh(*args, resolution=24)
    v2, f2 = extract_mesh(*args, resolution=24, chunk_points=100)
    np.testing.assert_array_equal(f1, f2)
    np.testing.assert_allclose(v1, v2, atol=1e-12)


def test_grid_axes_closed_form():
    xs, ys, zs = grid_axes_m([0, 0, 0], [2, 1, 1], resolution=5)
    np.testing.assert_allclose(xs, [0, 0.5, 1, 1.5, 2])
    np.testing.assert_allclose(ys, [0, 0.5, 1])
    xs, ys, zs = grid_axes_m([0, 0, 0], [1, 1, 0.7], voxel_size_m=0.25)
    np.testing.assert_allclose(np.diff(zs), 0.25)
    assert len(zs) == 3 and zs.mean() == pytest.approx(0.35)  # centred in the box


@pytest.mark.parametrize("kwargs, message", [
    ({}, "exactly one"),
    ({"resolution": 8, "voxel_size_m": 0.1}, "exactly one"),
    ({"resolution": 1}, "resolution"),
    ({"voxel_size_m": -1.0}, "voxel_size_m"),
    ({"voxel_size_m": 1e-4}, "too large"),
    ({"resolution": 8, "min_component_area_fraction": 1.0}, "min_component_area_fraction"),
])
def test_bad_arguments(kwargs, message):
    with pytest.raises(ValueError, match=message):
        extract_mesh(_box, [-4, -3, -1], [4, 3, 6], **kwargs)


def test_bad_box_and_bad_sdf():
    with pytest.raises(ValueError, match="must exceed"):
        extract_mesh(_box, [1, 0, 0], [0, 1, 1], resolution=8)
    with pytest.raises(ValueError, match="NaN"):
        extract_mesh(lambda p: np.full(len(p), np.nan), [0] * 3, [1] * 3, resolution=8)
    with pytest.raises(ValueError, match="shape"):
        extract_mesh(lambda p: np.zeros((len(p), 2)), [0] * 3, [1] * 3, resolution=8)


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_no_zero_crossing_is_a_clear_error(sign):
    with pytest.raises(ValueError, match="no zero crossing"):
        extract_mesh(lambda p: np.full(len(p), sign), [0] * 3, [1] * 3, resolution=8)


def test_small_components_are_removed():
    def two(p):
        return np.minimum(_sphere([0, 0, 0], 1.0)(p), _sphere([2, 0, 0], 0.2)(p))

    v, f = extract_mesh(two, [-1.5, -1.5, -1.5], [3, 1.5, 1.5], voxel_size_m=0.05)
    kept_v, kept_f = extract_mesh(two, [-1.5, -1.5, -1.5], [3, 1.5, 1.5], voxel_size_m=0.05,
                                  min_component_area_fraction=0.1)
    assert v[:, 0].max() > 2.1 and kept_v[:, 0].max() < 1.01  # the small sphere (4 %) is gone
    assert len(np.unique(kept_f)) == len(kept_v)  # no unused vertex left
    small = remove_small_components(v, f, 0.01)  # 4 % > 1 %: both stay
    assert len(small[1]) == len(f)


def test_labels_and_colours():
    v, f = extract_mesh(_sphere([0, 0, 0], 1.0), [-1.5] * 3, [1.5] * 3, resolution=32)
    labels = label_vertices(v, lambda p: (p[:, 2] > 0).astype(int) * 2)
    assert labels.dtype == np.uint8 and set(np.unique(labels)) == {0, 2}
    # colour = (view_dir + 1) / 2 with view_dir = -normal: the bottom of the sphere looks up
    rgb = color_vertices(v, f, lambda p, d: (d + 1) / 2)
    bottom = np.argmin(v[:, 2])
    assert rgb[bottom, 2] > 250 and abs(int(rgb[bottom, 0]) - 128) < 10
    with pytest.raises(ValueError, match="class ids outside"):
        label_vertices(v, lambda p: np.full(len(p), 9))


def test_ply_round_trip(tmp_path):
    v, f = extract_mesh(_box, [-4, -3, -1], [4, 3, 6], resolution=20)
    labels = (np.arange(len(v)) % 6).astype(np.uint8)
    rgb = np.random.default_rng(0).integers(0, 256, (len(v), 3)).astype(np.uint8)
    path = tmp_path / "mesh.ply"
    write_semantic_ply(path, v, f, labels, rgb)
    v2, f2, labels2, rgb2 = read_semantic_ply(path)
    np.testing.assert_allclose(v2, v, atol=1e-5)  # stored as float32
    np.testing.assert_array_equal(f2, f)
    np.testing.assert_array_equal(labels2, labels)
    np.testing.assert_array_equal(rgb2, rgb)
    tm = trimesh.load(path, process=False)  # what viewers see: geometry and vertex colours
    assert len(tm.faces) == len(f)
    np.testing.assert_array_equal(tm.visual.vertex_colors[:, :3], rgb)


def test_ply_errors(tmp_path):
    with pytest.raises(ValueError, match="does not exist"):
        read_semantic_ply(tmp_path / "missing.ply")
    plain = tmp_path / "plain.ply"
    trimesh.creation.box().export(plain)
    with pytest.raises(ValueError, match="no per-vertex 'label'"):
        read_semantic_ply(plain)
    v = np.zeros((3, 3))
    with pytest.raises(ValueError, match="uint8"):
        write_semantic_ply(plain, v, [[0, 1, 2]], np.zeros(3), np.zeros((3, 3)))
    with pytest.raises(ValueError, match="vertex_labels"):
        write_semantic_ply(plain, v, [[0, 1, 2]], np.zeros(2), np.zeros((3, 3), np.uint8))
