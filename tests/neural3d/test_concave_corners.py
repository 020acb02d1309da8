"""neural3d.extraction.concave_corners: walls continued to a concave corner the field filled.

The stage assumes sharp corners: a fillet or chamfer in a concave corner is the trained
field's doing (docs/neural3d-extract.md). The meshes are L-shaped prisms (footprint
10 x 10 m with a 6 x 6 m notch, 6 m high), each test stating the building it stands for
and taking its truth from that building's outline:

- the L with its inner corner cut by a chamfer with legs of ``LEG_M``, as a field leaves
  it: the building is the sharp L (40 m of walls, 240 m² of facade);
- the same mesh taken as built: the truth is the chamfered L's (39.3 m, 235.8 m²) and the
  stage counts the sharp L's, its stated bias;
- the sharp L meshed from its exact signed distance
  (:class:`neural3d.extraction.oracle.OracleField`), as a perfect field gives it: the stage
  leaves it within 0.1 m².
"""


import numpy as np
import pytest
import trimesh
from shapely.geometry import Polygon

from envelope.classes import SemanticClass
from neural3d.extraction.measure import measure_semantic_mesh
from neural3d.extraction.measure_config import MeasureConfig, MeasureStages

pytestmark = pytest.mark.slow  # every test here measures fields sampled on dense grids

HEIGHT_M, LEG_M = 6.0, 1.2
WALL, ROOF, OTHER = int(SemanticClass.WALL), int(SemanticClass.ROOF), int(SemanticClass.OTHER)
NO_CORNERS = MeasureConfig(stages=MeasureStages(concave_corner_fill=False))
CELL_ROUNDING_M2 = 0.1  # 0.1 m probe cells: under 2 cm per row at a wall's end, over 6 m


def _ring(leg_m=LEG_M, inner_x_m=4.0):
    """The L's outline (counter-clockwise, m), its inner corner cut by a chamfer with legs
    of ``leg_m`` (0: sharp)."""
    return [(0, 0), (10, 0), (10, 4), (inner_x_m + leg_m, 4), (inner_x_m, 4 + leg_m),
            (inner_x_m, 10), (0, 10)] if leg_m > 0 else [
            (0, 0), (10, 0), (10, 4), (inner_x_m, 4), (inner_x_m, 10), (0, 10)]


def _facade_truth_m2(leg_m=LEG_M):
    """Gross facade of the prism on ``_ring(leg_m)``: its perimeter times its height."""
    return Polygon(_ring(leg_m)).length * HEIGHT_M


def _prism(leg_m):
    """The prism as a trimesh; face classes: walls wall, top roof, bottom other."""
    mesh = trimesh.creation.extrude_polygon(Polygon(_ring(leg_m)), HEIGHT_M)
    normal_z = mesh.face_normals[:, 2]
    return mesh, np.where(normal_z > 0.5, ROOF, np.where(normal_z < -0.5, OTHER, WALL))


def _l_prism(leg_m=LEG_M, *, max_edge_m=0.1):
    """Vertices, faces and vertex labels of the chamfered L (walls class wall, top roof,
    bottom other; each face has its own vertices so that labels follow faces), cut into
    triangles of at most ``max_edge_m`` as marching cubes would."""
    mesh, _ = _prism(leg_m)
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


@pytest.fixture(scope="module")
def chamfered():
    """The chamfered L measured without and with the stage."""
    v, f, lab = _l_prism()
    return measure_semantic_mesh(v, f, lab, config=NO_CORNERS), measure_semantic_mesh(v, f, lab)


@pytest.mark.slow
def test_a_corner_the_field_filled_is_measured_as_the_sharp_l_it_stands_for(chamfered):
    truth_m2 = _facade_truth_m2(0.0)  # the building: the sharp L, 240 m²
    before, after = chamfered
    # Without the rule the chamfer (1.2 m legs, more than plane_slab_m in front of both
    # walls beyond its first 0.4 m) is counted partly as facade near no plane and the
    # inner walls lose what it hides: about 5 m² of 240.
    assert before.facade_area_m2 < truth_m2 - 4.0
    assert before.ungrouped_facade_area_m2 > 1.0
    # With it each inner wall is 6 m long again, up to the cells' rounding at the wall's
    # end, and the chamfer no longer counts alone.
    assert [x.facade_area_m2 for x in _inner(after)] == pytest.approx(
        [6.0 * HEIGHT_M] * 2, abs=CELL_ROUNDING_M2)
    assert after.facade_area_m2 == pytest.approx(truth_m2, abs=CELL_ROUNDING_M2)
    assert after.ungrouped_facade_area_m2 == pytest.approx(0.0, abs=1e-9)
    assert after.wall_area_m2 == pytest.approx(after.facade_area_m2)


def test_a_chamfer_as_built_is_counted_as_a_sharp_corner_the_stages_stated_bias(chamfered):
    """The same mesh as a building whose inner corner really is chamfered: the truth is
    235.8 m²; the stage, which cannot tell a built chamfer from a field's, counts each
    leg instead of the chamfer's width: + 6 m x (2 x 1.2 - 1.2 x sqrt 2) m = +4.2 m²."""
    before, after = chamfered
    truth_m2 = _facade_truth_m2()
    assert truth_m2 == pytest.approx(235.78, abs=0.01)
    bias_m2 = HEIGHT_M * (2 * LEG_M - np.sqrt(2) * LEG_M)
    assert after.facade_area_m2 - truth_m2 == pytest.approx(bias_m2, abs=CELL_ROUNDING_M2)
    # without the stage the built chamfer counts where it is near a plane or near vertical
    assert before.facade_area_m2 == pytest.approx(truth_m2, abs=1.0)


@pytest.mark.slow
def test_a_sharp_corner_from_a_perfect_field_is_left_where_it_is():
    """The sharp L meshed by marching cubes (0.15 m voxels) from its exact signed distance:
    the corner is rounded by under a voxel, and the stage moves the facade by under
    0.1 m² (the mesh's own shortfall, about a voxel's height of wall at the roof and the
    ground, is the count's, not the stage's)."""
    from envelope.mesh import LabelledMesh
    from neural3d.extraction.meshing import extract_mesh, label_vertices
    from neural3d.extraction.oracle import OracleField

    mesh, face_label = _prism(0.0)
    truth = LabelledMesh(mesh.vertices, mesh.faces, face_label, np.zeros(len(face_label)))
    voxel_m = 0.15
    lo, hi = np.array([-1.0137, -1.0291, -1.0173]), np.array([11.0, 11.0, 7.0])  # off-grid
    field = OracleField(truth, "l", voxel_m=voxel_m, box_min_m=lo, box_max_m=hi)
    v, f = extract_mesh(field.sdf, lo, hi, voxel_size_m=voxel_m)
    lab = label_vertices(v, field.labels)
    on = measure_semantic_mesh(v, f, lab)
    off = measure_semantic_mesh(v, f, lab, config=NO_CORNERS)
    assert on.facade_area_m2 == pytest.approx(off.facade_area_m2, abs=CELL_ROUNDING_M2)
    assert on.facade_area_m2 == pytest.approx(_facade_truth_m2(0.0), rel=0.03)
    assert len(_inner(on)) == 2


@pytest.mark.slow
def test_a_sharp_corner_and_a_convex_one_are_left_alone():
    v, f, lab = _l_prism(0.0)
    sharp = measure_semantic_mesh(v, f, lab)
    assert sharp.facade_area_m2 == pytest.approx(_facade_truth_m2(0.0), abs=0.05)
    assert sharp.facade_area_m2 == pytest.approx(
        measure_semantic_mesh(v, f, lab, config=NO_CORNERS).facade_area_m2, abs=1e-9)


@pytest.mark.slow
def test_a_corner_further_than_the_longest_gap_is_not_filled():
    v, f, lab = _l_prism(2.0)  # legs of 2 m: longer than corner_max_gap_m (1.5 m)
    assert measure_semantic_mesh(v, f, lab).facade_area_m2 == pytest.approx(
        measure_semantic_mesh(v, f, lab, config=NO_CORNERS).facade_area_m2, abs=1e-9)


def test_config_is_checked():
    with pytest.raises(ValueError, match="corner_max_gap_m"):
        MeasureConfig(corner_max_gap_m=0.0)
