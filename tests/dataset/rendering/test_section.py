"""dataset.rendering.section: footprints of hollow, disjoint and courtyard solids."""

import numpy as np
import pytest
import trimesh
from shapely.geometry import Polygon

from dataset.rendering.section import cross_section_footprint
from envelope.geometry.raycast import Raycaster


def _footprint(mesh, z):
    return cross_section_footprint(Raycaster.from_triangles(mesh.vertices, mesh.faces), z)


def test_hollow_box_with_roof_is_filled():
    # A 10 x 6 m box with a roofed 8 x 4 m room inside (inner shell inverted).
    outer = trimesh.creation.box([10.0, 6.0, 4.0])
    room = trimesh.creation.box([8.0, 4.0, 3.0])
    room.invert()
    mesh = trimesh.util.concatenate([outer, room])
    fp = _footprint(mesh, 0.0)
    assert fp.geom_type == "Polygon" and len(fp.interiors) == 0
    assert fp.area == pytest.approx(60.0, rel=1e-9)
    assert len(fp.exterior.coords) == 5  # collinear section vertices dropped


def test_open_courtyard_stays_a_hole():
    square = [(-5, -5), (5, -5), (5, 5), (-5, 5)]
    yard = [(-2, -2), (-2, 2), (2, 2), (2, -2)]
    ring = trimesh.creation.extrude_polygon(Polygon(square, [yard]), 4.0)
    fp = _footprint(ring, 1.0)
    assert len(fp.interiors) == 1
    assert fp.area == pytest.approx(84.0, rel=1e-9)


def test_disjoint_buildings_give_a_multipolygon():
    a = trimesh.creation.box([2.0, 2.0, 2.0])
    b = trimesh.creation.box([2.0, 2.0, 2.0])
    b.apply_translation([5.0, 0.0, 0.0])
    fp = _footprint(trimesh.util.concatenate([a, b]), 0.0)
    assert fp.geom_type == "MultiPolygon" and fp.area == pytest.approx(8.0)


def test_plane_missing_the_mesh_is_refused():
    box = trimesh.creation.box()
    with pytest.raises(ValueError, match="misses the mesh"):
        _footprint(box, 3.0)
    assert np.isfinite(_footprint(box, 0.1).area)
