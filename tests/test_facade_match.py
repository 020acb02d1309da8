"""neural3d.facade_match: mesh facade groups take the truth's facade ids."""

import numpy as np
import pytest
import trimesh
from sdf_shapes import banded_labels, box_sdf, cylinder_sdf, truth_mesh_of

from dataset.mesh import LabelledMesh
from neural3d.facade_match import facades_by_truth
from neural3d.measure import MeasureConfig, measure_semantic_mesh
from neural3d.meshing import extract_mesh, label_vertices


def _measured(sdf, lo, hi, voxel_size_m):
    v, f = extract_mesh(sdf, lo, hi, voxel_size_m=voxel_size_m)
    labels = label_vertices(v, banded_labels(sdf, (3.0, 6.0)))
    return v, f, labels, measure_semantic_mesh(v, f, labels)


def test_box_groups_take_truth_ids():
    def sdf(p):
        return box_sdf(p, [-3, -2, 0], [3, 2, 10])

    v, f, labels, m = _measured(sdf, [-4, -3, -1], [4, 3, 11], 0.1)
    truth = truth_mesh_of(trimesh.creation.box(
        extents=[6, 4, 10], transform=trimesh.transformations.translation_matrix([0, 0, 5])))
    matched, unmatched = facades_by_truth(v, f, labels, m, truth)
    assert unmatched == () and sorted(matched) == [1, 2, 3, 4]  # azimuth 0, 90, 180, 270
    for facade_id, azimuth in zip((1, 2, 3, 4), (0, 90, 180, 270)):
        assert matched[facade_id].index == facade_id
        assert round(matched[facade_id].azimuth_deg) % 360 == azimuth
        assert matched[facade_id].wwr == pytest.approx(0.3, abs=0.01)


def test_curved_segments_merge_into_one_facade():
    def sdf(p):
        return cylinder_sdf(p, [0, 0], 5.0, 0.0, 10.0)

    v, f, labels, m = _measured(sdf, [-6, -6, -1], [6, 6, 11], 0.12)
    cylinder = trimesh.creation.cylinder(radius=5.0, height=10.0, sections=128,
                                         transform=trimesh.transformations.translation_matrix(
                                             [0, 0, 5]))
    matched, unmatched = facades_by_truth(v, f, labels, m, truth_mesh_of(cylinder, curved=True))
    assert len(m.facades) > 1 and unmatched == () and list(matched) == [1]
    whole = matched[1]
    grouped_m2 = m.facade_area_m2 - m.ungrouped_facade_area_m2  # rims tilt too much to group
    assert whole.facade_area_m2 == pytest.approx(grouped_m2, rel=1e-9)
    assert whole.wwr == pytest.approx(0.3, abs=0.01)
    assert whole.width_m == pytest.approx(2 * np.pi * 5, rel=0.02)  # area / height: arc length


def test_no_truth_facade_leaves_groups_unmatched():
    def sdf(p):
        return box_sdf(p, [-3, -2, 0], [3, 2, 10])

    v, f, labels, m = _measured(sdf, [-4, -3, -1], [4, 3, 11], 0.2)
    roof_only = LabelledMesh(np.eye(3), [[0, 1, 2]], [3], [0])
    matched, unmatched = facades_by_truth(v, f, labels, m, roof_only)
    assert matched == {} and unmatched == (0, 1, 2, 3)
    with pytest.raises(ValueError, match="does not belong"):
        facades_by_truth(v, f, labels, m, roof_only,
                         config=MeasureConfig(min_facade_area_m2=50.0))
    with pytest.raises(ValueError, match="spacing_m"):
        facades_by_truth(v, f, labels, m, roof_only, spacing_m=0.0)
