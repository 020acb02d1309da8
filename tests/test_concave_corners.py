"""neural3d.extraction.concave_corners: walls continued to a concave corner the field filled.

The mesh is an L-shaped prism (footprint 10 x 10 m with a 6 x 6 m notch, 6 m high) whose
inner corner is cut by a chamfer with legs of ``LEG_M``: what a trained field leaves at the
inner corner of an L. The sharp L has 40 m of walls, 240 m² of facade.
"""


import numpy as np
import pytest
import trimesh
from shapely.geometry import Polygon

from dataset.core.classes import SemanticClass
from neural3d.extraction.measure import measure_semantic_mesh
from neural3d.extraction.measure_config import MeasureConfig, MeasureStages

HEIGHT_M, LEG_M = 6.0, 1.2
WALL, ROOF, OTHER = int(SemanticClass.WALL), int(SemanticClass.ROOF), int(SemanticClass.OTHER)
NO_CORNERS = MeasureConfig(stages=MeasureStages(concave_corner_fill=False))


def _l_prism(leg_m=LEG_M, *, inner_x_m=4.0, max_edge_m=0.1):
    """Vertices, faces and vertex labels of the chamfered L (walls class wall, top roof,
    bottom other; each face has its own vertices so that labels follow faces), cut into
    triangles of at most ``max_edge_m`` as marching cubes would."""
    ring = [(0, 0), (10, 0), (10, 4), (inner_x_m + leg_m, 4), (inner_x_m, 4 + leg_m),
            (inner_x_m, 10), (0, 10)] if leg_m > 0 else [
            (0, 0), (10, 0), (10, 4), (inner_x_m, 4), (inner_x_m, 10), (0, 10)]
    mesh = trimesh.creation.extrude_polygon(Polygon(ring), HEIGHT_M)
    mesh = trimesh.Trimesh(*trimesh.remesh.subdivide_to_size(mesh.vertices, mesh.faces,
                                                             max_edge=max_edge_m))
    tri = mesh.triangles
    normal_z = mesh.face_normals[:, 2]
    face_label = np.where(normal_z > 0.5, ROOF, np.where(normal_z < -0.5, OTHER, WALL))
    return (tri.reshape(-1, 3), np.arange(3 * len(tri)).reshape(-1, 3),
            np.repeat(face_label, 3))


def _inner(measurement):
    """The inner walls' facades: facing +y at y = 4 and +x at x = 4."""
    return sorted((f for f in measurement.facades if
                   (round(f.azimuth_deg) % 360 == 90 and abs(f.offset_m - 4) < 0.5)
                   or (round(f.azimuth_deg) % 360 == 0 and abs(f.offset_m - 4) < 0.5)),
                  key=lambda f: f.azimuth_deg)


def test_each_inner_wall_is_continued_to_the_corner():
    v, f, lab = _l_prism()
    before = measure_semantic_mesh(v, f, lab, config=NO_CORNERS)
    after = measure_semantic_mesh(v, f, lab)
    # Without the rule the chamfer (1.2 m legs, more than plane_slab_m in front of both
    # walls beyond its first 0.4 m) is counted partly as facade near no plane and the
    # inner walls lose what it hides: about 5 m² of 240.
    assert before.facade_area_m2 < 240.0 - 4.0
    assert before.ungrouped_facade_area_m2 > 1.0
    # With it each inner wall is 6 m long again, up to the cells' rounding at the wall's
    # end (0.1 m cells: under 2 cm per row, 0.1 m² over the 6 m height), and the chamfer
    # no longer counts alone.
    assert [x.facade_area_m2 for x in _inner(after)] == pytest.approx(
        [6.0 * HEIGHT_M] * 2, abs=0.1)
    assert after.facade_area_m2 == pytest.approx(240.0, abs=0.1)
    assert after.ungrouped_facade_area_m2 == pytest.approx(0.0, abs=1e-9)
    assert after.wall_area_m2 == pytest.approx(after.facade_area_m2)


def test_a_sharp_corner_and_a_convex_one_are_left_alone():
    v, f, lab = _l_prism(0.0)
    sharp = measure_semantic_mesh(v, f, lab)
    assert sharp.facade_area_m2 == pytest.approx(240.0, abs=0.05)
    assert sharp.facade_area_m2 == pytest.approx(
        measure_semantic_mesh(v, f, lab, config=NO_CORNERS).facade_area_m2, abs=1e-9)


def test_a_corner_further_than_the_longest_gap_is_not_filled():
    v, f, lab = _l_prism(2.0)  # legs of 2 m: longer than corner_max_gap_m (1.5 m)
    assert measure_semantic_mesh(v, f, lab).facade_area_m2 == pytest.approx(
        measure_semantic_mesh(v, f, lab, config=NO_CORNERS).facade_area_m2, abs=1e-9)


def test_config_is_checked():
    with pytest.raises(ValueError, match="corner_max_gap_m"):
        MeasureConfig(corner_max_gap_m=0.0)
