"""Plane-sampled window area: an analytic box with recessed windows is measured exactly."""

import numpy as np
import pytest
from sdf_shapes import box_sdf

from dataset.core.classes import SemanticClass
from neural3d.extraction.meshing import extract_mesh
from neural3d.extraction.plane_sampling import PlaneExtent, plane_extents, plane_sampled_areas

LO, HI = np.array([0.0, 0.0, 0.0]), np.array([10.0, 6.0, 8.0])
# Two windows on the +x wall (y, z ranges in m), recessed 0.2 m: 2 x 1.2 x 1.5 = 3.6 m².
WINDOWS = (((1.0, 2.2), (2.0, 3.5)), ((3.6, 4.8), (2.0, 3.5)))
RECESS_M = 0.2
WINDOW_M2 = 3.6
WALL_M2 = 6.0 * 8.0 - WINDOW_M2
# Cell edges fall on the window edges (multiples of 0.05 m): measured error 0 on both areas.
AREA_TOL = 0.005  # relative


def building_sdf(p):
    d = box_sdf(p, LO, HI)
    for (y0, y1), (z0, z1) in WINDOWS:
        recess = box_sdf(p, [HI[0] - RECESS_M, y0, z0], [HI[0] + 1.0, y1, z1])
        d = np.maximum(d, -recess)
    return d


def building_labels(p):
    labels = np.full(len(p), SemanticClass.WALL, dtype=np.int64)
    labels[p[:, 2] > HI[2] - 1e-3] = SemanticClass.ROOF
    for (y0, y1), (z0, z1) in WINDOWS:
        inside = ((p[:, 1] > y0) & (p[:, 1] < y1) & (p[:, 2] > z0) & (p[:, 2] < z1)
                  & (p[:, 0] > HI[0] - RECESS_M - 0.05))
        labels[inside] = SemanticClass.WINDOW
    return labels


def test_recessed_windows_count_their_projected_area_exactly():
    east = PlaneExtent(0.0, HI[0], 0.0, 6.0, 0.0, 8.0)  # +x wall; u runs along +y
    areas = plane_sampled_areas(building_sdf, building_labels, east, cell_m=0.05, depth_m=0.5)
    assert areas.window_m2 == pytest.approx(WINDOW_M2, rel=AREA_TOL)
    assert areas.wall_m2 == pytest.approx(WALL_M2, rel=AREA_TOL)  # reveals add nothing
    assert areas.door_m2 == 0.0


def test_cells_beyond_the_wall_or_behind_it_are_no_facade():
    wide = PlaneExtent(0.0, HI[0], -2.0, 8.0, 0.0, 10.0)  # 2 m past every edge
    areas = plane_sampled_areas(building_sdf, building_labels, wide, cell_m=0.05, depth_m=0.5)
    assert areas.window_m2 + areas.wall_m2 == pytest.approx(48.0, rel=AREA_TOL)
    inner = PlaneExtent(0.0, 5.0, 0.0, 6.0, 0.0, 8.0)  # a plane through the middle
    assert plane_sampled_areas(building_sdf, building_labels, inner, cell_m=0.1,
                               depth_m=0.5).wall_m2 == 0.0


def test_plane_extents_of_a_meshed_box():
    vertices, faces = extract_mesh(lambda p: box_sdf(p, LO, HI), LO - 1, HI + 1, resolution=48)
    planes = ((0.0, 10.0), (90.0, 6.0), (180.0, 0.0), (270.0, 0.0), (45.0, 30.0))
    extents = plane_extents(vertices, faces, planes, slab_m=0.4, max_angle_deg=60.0)
    assert len(extents) == 4  # the plane far from the box has no triangles
    east = extents[0]
    voxel = 12.0 / 48
    assert east.u_min_m == pytest.approx(0.0, abs=voxel) and east.u_max_m == pytest.approx(
        6.0, abs=voxel)
    assert east.z_min_m == pytest.approx(0.0, abs=voxel) and east.z_max_m == pytest.approx(
        8.0, abs=voxel)
