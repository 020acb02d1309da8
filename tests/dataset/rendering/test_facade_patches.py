"""Facade patches read off the mesh: the box's four facades, sectors of a curved facade."""

from dataclasses import replace

import numpy as np
import pytest

from dataset.rendering.facade_patches import facade_patches
from envelope.classes import SemanticClass
from envelope.mesh import LabelledMesh
from envelope.truth import Building


def test_box_facades_have_exact_geometry(box_building):
    patches = facade_patches(box_building)
    assert [p.facade_id for p in patches] == [1, 2, 3, 4]
    expected_normals = [(0, -1, 0), (1, 0, 0), (0, 1, 0), (-1, 0, 0)]
    expected_centres = [(0, -6, 4.5), (10, 0, 4.5), (0, 6, 4.5), (-10, 0, 4.5)]
    for p, n, c in zip(patches, expected_normals, expected_centres):
        np.testing.assert_allclose(p.normal, n, atol=1e-12)
        np.testing.assert_allclose(p.centre_m, c, atol=1e-12)
        assert p.width_m == pytest.approx(box_building.truth.facade(p.facade_id).width_m)
        assert p.height_m == pytest.approx(9.0)
        # Corners: bottom-left, bottom-right, top-right, top-left seen from outside.
        np.testing.assert_allclose(p.corners_m[1] - p.corners_m[0], p.width_m * p.right)
        np.testing.assert_allclose(p.corners_m[3] - p.corners_m[0], [0, 0, 9.0])
        assert np.cross(p.right, [0, 0, 1.0]) @ p.normal == pytest.approx(1.0)
        assert (box_building.mesh.face_facade[p.face_index] == p.facade_id).all()


def _half_cylinder(radius_m=10.0, height_m=6.0, segments=36) -> LabelledMesh:
    """A curved wall over azimuths 0..180 deg, facade 1, outward normals."""
    angles = np.linspace(0, np.pi, segments + 1)
    ring = np.stack([radius_m * np.cos(angles), radius_m * np.sin(angles)], axis=1)
    bottom = np.column_stack([ring, np.zeros(len(ring))])
    top = np.column_stack([ring, np.full(len(ring), height_m)])
    vertices = np.concatenate([bottom, top])
    n = len(ring)
    faces = []
    for i in range(segments):
        faces += [[i, i + 1, n + i + 1], [i, n + i + 1, n + i]]
    return LabelledMesh(vertices, np.array(faces), [SemanticClass.WALL] * len(faces),
                        [1] * len(faces))


def test_curved_facade_is_cut_into_sectors(box_building):
    mesh = _half_cylinder()
    facade = replace(box_building.truth.facades[0], id=1, normal=(0.0, 1.0, 0.0), curved=True)
    building = Building(mesh, replace(box_building.truth, facades=(facade,)))
    # Face normals span 5..175 deg of azimuth: 170 deg -> three sectors of at most 60 deg.
    patches = facade_patches(building, sector_deg=60.0)
    assert len(patches) == 3 and all(p.facade_id == 1 for p in patches)
    azimuths = sorted(np.degrees(np.arctan2(p.normal[1], p.normal[0])) for p in patches)
    np.testing.assert_allclose(azimuths, [30.0, 90.0, 150.0], atol=3.0)
    assert sum(len(p.face_index) for p in patches) == len(mesh.faces)
    # Without the curved flag, the facade is one patch along the truth normal.
    flat = Building(mesh, replace(building.truth, facades=(replace(facade, curved=False),)))
    (patch,) = facade_patches(flat)
    np.testing.assert_allclose(patch.normal, [0, 1, 0])
    assert patch.width_m == pytest.approx(20.0)


def test_facade_without_truth_uses_mean_face_normal(box_building):
    building = Building(box_building.mesh, replace(box_building.truth, facades=()))
    patches = facade_patches(building)
    np.testing.assert_allclose(patches[1].normal, [1, 0, 0], atol=1e-12)


def test_roof_like_facade_is_skipped_with_a_warning(box_building):
    facades = box_building.truth.facades
    tilted = replace(facades[0], normal=(0.0, 0.0, 1.0))
    building = Building(box_building.mesh,
                        replace(box_building.truth, facades=(tilted, *facades[1:])))
    with pytest.warns(UserWarning, match="facade 1 has no horizontal normal"):
        patches = facade_patches(building)
    assert [p.facade_id for p in patches] == [2, 3, 4]
    with pytest.raises(ValueError, match="sector_deg"):
        facade_patches(building, sector_deg=0)
