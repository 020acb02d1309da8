"""neural3d.extraction.facade_planes: planes of a meshed box and each triangle's shadow on them."""

import numpy as np
import pytest
from sdf_shapes import banded_labels, box_sdf

from envelope.classes import FACADE_CLASSES
from envelope.mesh import triangle_normals
from neural3d.extraction.facade_groups import class_area_m2, group_facade_faces
from neural3d.extraction.facade_planes import (
    azimuth_offset,
    circular_mean_deg,
    project_onto_facade_planes,
)
from neural3d.extraction.measure_config import MeasureConfig
from neural3d.extraction.meshing import extract_mesh, label_vertices


def _box_sdf(p):
    # 6.06 x 4.06 x 10 m; the vertical edges lie 0.03 m past a grid sample on both axes,
    # so marching cubes cuts them with 45-degree chamfers
    return box_sdf(p, [-3.03, -2.03, 0], [3.03, 2.03, 10])


@pytest.fixture(scope="module")
def box_planes():
    v, f = extract_mesh(_box_sdf, [-4, -3, -1], [4, 3, 11], voxel_size_m=0.1)
    labels = label_vertices(v, banded_labels(_box_sdf, (3.0, 6.0)))
    facade_area = class_area_m2(v, f, labels)[:, list(FACADE_CLASSES)].sum(axis=1)
    group = group_facade_faces(v, f, labels)
    planes = project_onto_facade_planes(v, f, facade_area, group, config=MeasureConfig())
    return v, f, facade_area, planes


def test_box_planes_are_its_four_walls(box_planes):
    _, _, _, planes = box_planes
    np.testing.assert_allclose(planes.azimuth_deg % 360, [0, 90, 180, 270], atol=0.5)
    np.testing.assert_allclose(planes.offset_m, [3.03, 2.03, 3.03, 2.03], atol=0.05)


def test_flat_wall_counts_in_full_and_corners_on_both_walls(box_planes):
    v, f, facade_area, planes = box_planes
    n = triangle_normals(v[f])
    on_wall = (facade_area > 0) & (np.abs(n[:, :2]).max(axis=1) > 0.999)
    # a triangle of a flat wall counts once, with its whole area
    np.testing.assert_allclose(planes.weight[on_wall].sum(axis=1), 1.0, atol=1e-6)
    # a 45-degree chamfer at a vertical edge projects onto both walls: sqrt(2) in all (its
    # shares are plain shadows: no strip cosine on a corner)
    chamfer = (facade_area > 0) & np.isclose(np.abs(n[:, 0]), np.abs(n[:, 1]), atol=1e-3) \
        & (np.abs(n[:, 2]) < 1e-6)
    assert chamfer.sum() >= 4 * 90  # at least one per vertical edge and voxel of height
    np.testing.assert_allclose(planes.weight[chamfer].sum(axis=1), np.sqrt(2), atol=1e-6)
    assert ((planes.weight[chamfer] > 0).sum(axis=1) == 2).all()
    # the roof and the underside are no facade
    assert planes.weight[facade_area == 0].sum() == 0 and planes.residual.sum() == 0


def test_box_gross_area_is_its_perimeter_times_height(box_planes):
    _, _, facade_area, planes = box_planes
    total = float((facade_area * planes.weight.sum(axis=1)).sum())
    # the vertical edges are restored; the cut top and bottom edges (chamfers labelled roof
    # and background) lose up to a voxel each: 2 x 20.24 m x 0.1 m (2.03 m², 1 %, measured)
    perimeter_m = 2 * (6.06 + 4.06)
    assert perimeter_m * 10 - 2 * perimeter_m * 0.1 <= total <= perimeter_m * 10 + 1e-6


def test_azimuth_helpers():
    mean = circular_mean_deg(np.array([350.0, 20.0]), np.ones(2))
    assert mean == pytest.approx(5.0)
    normals = np.array([[0.0, 1.0, 0.0], [0.0, 1.0, 0.0]])
    az, offset = azimuth_offset(normals, np.array([[0.0, 2.0], [1.0, 4.0]]), np.array([1.0, 3.0]))
    assert az == pytest.approx(90.0) and offset == pytest.approx(3.5)
    tri = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 0, 0], [0, 0, 0], [0, 0, 0]]], float)
    np.testing.assert_allclose(triangle_normals(tri), [[0, 0, 1], [0, 0, 0]])
