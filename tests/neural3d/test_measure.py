"""neural3d.extraction.measure: class areas, WWR and facade grouping on meshes of analytic
shapes."""

import numpy as np
import pytest
from sdf_shapes import banded_labels, box_sdf, cylinder_sdf, l_prism_sdf

from envelope.classes import SemanticClass
from neural3d.extraction.facade_groups import class_area_m2, group_facade_faces
from neural3d.extraction.measure import measure_semantic_mesh
from neural3d.extraction.measure_config import MeasureConfig, MeasureStages
from neural3d.extraction.meshing import extract_mesh, label_vertices

WALL, WINDOW, ROOF = int(SemanticClass.WALL), int(SemanticClass.WINDOW), int(SemanticClass.ROOF)


def _semantic_mesh(sdf, lo, hi, band_z_m, voxel_size_m):
    v, f = extract_mesh(sdf, lo, hi, voxel_size_m=voxel_size_m)
    return v, f, label_vertices(v, banded_labels(sdf, band_z_m))


@pytest.fixture(scope="module")
def banded_box():
    """6 x 4 x 10 m box, window band 3 m < z < 6 m on every side: WWR = 3 / 10."""
    def sdf(p):
        return box_sdf(p, [-3, -2, 0], [3, 2, 10])

    return _semantic_mesh(sdf, [-4, -3, -1], [4, 3, 11], (3.0, 6.0), 0.08)


def test_triangle_area_is_shared_by_vertex_classes():
    v = np.array([[0, 0, 0], [2, 0, 0], [0, 3, 0], [0, 0, 1.0]])
    f = np.array([[0, 1, 2], [0, 1, 3]])
    areas = class_area_m2(v, f, np.array([WINDOW, WINDOW, WALL, ROOF]))
    np.testing.assert_allclose(areas[0, [WINDOW, WALL]], [3 * 2 / 3, 3 * 1 / 3])
    np.testing.assert_allclose(areas[1, [WINDOW, ROOF]], [1 * 2 / 3, 1 * 1 / 3])
    np.testing.assert_allclose(areas.sum(axis=1), [3.0, 1.0])


@pytest.mark.slow
def test_box_with_window_band(banded_box):
    m = measure_semantic_mesh(*banded_box)
    assert m.facade_area_m2 == pytest.approx(2 * (6 + 4) * 10, rel=0.01)
    # each edge of the band may land half a voxel (0.04 m) off, all around the 20 m perimeter
    assert m.window_area_m2 == pytest.approx(2 * (6 + 4) * 3, abs=20 * 0.08)
    assert m.wwr == pytest.approx(0.3, abs=0.01)
    assert m.facade_area_m2 == pytest.approx(m.wall_area_m2 + m.window_area_m2 + m.door_area_m2)
    assert [round(f.azimuth_deg) % 360 for f in m.facades] == [0, 90, 180, 270]
    for facade, width in zip(m.facades, (4, 6, 4, 6)):
        assert facade.wwr == pytest.approx(0.3, abs=0.01)
        assert facade.width_m == pytest.approx(width, abs=0.2)  # two voxels
        assert facade.height_m == pytest.approx(10, abs=0.2)
        # the cut vertical edges (one voxel wide) go to one neighbour or the other
        assert facade.facade_area_m2 == pytest.approx(width * 10, abs=10 * 2 * 0.08)
    np.testing.assert_allclose([f.offset_m for f in m.facades], [3, 2, 3, 2], atol=0.05)
    # centres: the middle of each side at half height (edge strips and voxels: 0.1 m)
    np.testing.assert_allclose([f.centre_m for f in m.facades],
                               [[3, 0, 5], [0, 2, 5], [-3, 0, 5], [0, -2, 5]], atol=0.1)


@pytest.mark.slow
def test_cylinder_curved_facade():
    def sdf(p):
        return cylinder_sdf(p, [1.0, -1.0], 5.0, 0.0, 10.0)

    v, f, labels = _semantic_mesh(sdf, [-5, -7, -1], [7, 5, 11], (2.0, 5.0), 0.1)
    m = measure_semantic_mesh(v, f, labels)
    # projection onto 1 m strips keeps the curve (a 5 m radius: -0.2 %); the cut top and
    # bottom rims lose up to a voxel each: 2 x 0.1 m x 31.4 m = 2 %
    assert m.facade_area_m2 == pytest.approx(2 * np.pi * 5 * 10, rel=0.02)
    assert m.facade_area_m2 <= 2 * np.pi * 5 * 10
    assert m.wwr == pytest.approx(0.3, abs=0.01)
    # no straight wall: greedy peaks are >= 30 degrees apart and leave no gap of 60, so the
    # curve is cut into segments 30 to 60 degrees wide
    assert 360 / 60 < len(m.facades) <= 360 / 30
    assert sum(fa.facade_area_m2 for fa in m.facades) == pytest.approx(m.facade_area_m2, rel=0.01)


@pytest.mark.slow
def test_l_prism_splits_parallel_walls():
    v, f, labels = _semantic_mesh(l_prism_sdf, [-1, -1, -1], [11, 13, 9], (2.0, 4.0), 0.1)
    m = measure_semantic_mesh(v, f, labels)
    # six walls: two face +x (x = 4 and x = 10) and two +y (y = 4 and y = 12)
    got = sorted((round(fa.azimuth_deg) % 360, round(fa.offset_m)) for fa in m.facades)
    assert got == [(0, 4), (0, 10), (90, 4), (90, 12), (180, 0), (270, 0)]
    assert m.wwr == pytest.approx(2 / 8, abs=0.01)


@pytest.mark.slow
def test_grouping_config_and_ungrouped_area(banded_box):
    v, f, labels = banded_box
    group = group_facade_faces(v, f, labels)
    assert group.shape == (len(f),) and set(np.unique(group)) == {-1, 0, 1, 2, 3}
    # the roof is no facade: only facade-class triangles may be grouped
    roof_only = (labels[f] == ROOF).all(axis=1)
    assert (group[roof_only] == -1).all()
    strict = measure_semantic_mesh(v, f, labels, config=MeasureConfig(
        stages=MeasureStages().without("plane_projection"), min_facade_area_m2=50.0))
    assert len(strict.facades) == 2  # only the 6 m wide (60 m²) facades stay
    assert strict.ungrouped_facade_area_m2 == pytest.approx(80, rel=0.02)
    # without planes every triangle counts: the groups only give the per-facade figures
    assert strict.facade_area_m2 == pytest.approx(
        sum(fa.facade_area_m2 for fa in strict.facades) + strict.ungrouped_facade_area_m2)
    ungrouped = measure_semantic_mesh(v, f, labels, config=MeasureConfig(
        stages=MeasureStages().without("grouping")))
    assert ungrouped.facades == () and ungrouped.facade_area_m2 == strict.facade_area_m2
    assert ungrouped.ungrouped_facade_area_m2 == pytest.approx(ungrouped.facade_area_m2, rel=1e-12)


def _recessed_box(voxel_size_m: float = 0.05, *, window_m: tuple[float, float] = (1.0, 1.2),
                  depth_m: float = 0.3):
    """6 x 4 x 10 m box with two ``window_m`` (width, height; default 1 x 1.2 m) windows per
    side, their bottom 4 m up, recessed ``depth_m``, and an underside.

    Labels: window on the pane and the reveals, roof on top, wall elsewhere, the
    underside (z = 0) included, as a neural field closing the building at the
    ground labels it. Truth: window 8 x 1.2 m², gross facade 200 m² (by default).
    """
    lo, hi = np.array([-3.0, -2.0, 0.0]), np.array([3.0, 2.0, 10.0])
    recesses = []
    for axis, size in ((0, 6.0), (1, 4.0)):  # windows on the faces normal to the other axis
        other = 1 - axis
        for side in (lo[other], hi[other]):
            for u0 in (-0.5 * size + 1.0, 0.5 * size - 2.0):
                r_lo, r_hi = np.array([0, 0, 4.0]), np.array([0, 0, 4.0 + window_m[1]])
                r_lo[axis], r_hi[axis] = u0, u0 + window_m[0]
                r_lo[other], r_hi[other] = side - depth_m, side + depth_m
                recesses.append((r_lo, r_hi))

    def sdf(p):
        cut = np.min([box_sdf(p, a, b) for a, b in recesses], axis=0)
        return np.maximum(box_sdf(p, lo, hi), -cut)

    def label(p):
        out = np.full(len(p), WALL)
        inside_recess = np.any([(p >= a - 0.01).all(1) & (p <= b + 0.01).all(1)
                                for a, b in recesses], axis=0)
        out[inside_recess] = WINDOW
        out[p[:, 2] > 10.0 - 0.01] = ROOF
        return out

    v, f = extract_mesh(sdf, [-4, -3, -1], [4, 3, 11], voxel_size_m=voxel_size_m)
    return v, f, label_vertices(v, label)


@pytest.mark.slow
def test_projected_counts_recesses_and_underside_once():
    v, f, labels = _recessed_box()
    m = measure_semantic_mesh(v, f, labels)
    # the openings' edges land up to half a voxel off: 8 windows x 4.4 m x 0.025 m = 0.9 m²
    assert m.window_area_m2 == pytest.approx(8 * 1.2, abs=0.9)
    assert m.facade_area_m2 == pytest.approx(200.0, rel=0.01)
    assert m.wwr == pytest.approx(9.6 / 200.0, abs=0.005)
    assert [round(fa.azimuth_deg) % 360 for fa in m.facades] == [0, 90, 180, 270]
    for facade in m.facades:
        assert facade.window_area_m2 == pytest.approx(2.4, abs=0.25)
    # counting every triangle adds the reveals (8 x 4.4 m x 0.3 m) and the 24 m² underside
    every = measure_semantic_mesh(v, f, labels, config=MeasureConfig(
        stages=MeasureStages().without("plane_projection", "visibility_cull")))
    assert every.window_area_m2 > m.window_area_m2 + 0.8 * 8 * 4.4 * 0.3
    assert every.facade_area_m2 > m.facade_area_m2 + 0.9 * 24.0


@pytest.mark.slow
def test_surfaces_inside_the_building_count_for_nothing():
    """A closed cavity inside the 6 x 4 x 10 m box (a blob a field may leave behind the
    windows): its 2 x (4 + 2) x 6 = 72 m² of walls are hidden from outside."""
    def sdf(p):
        return np.maximum(box_sdf(p, [-3, -2, 0], [3, 2, 10]), -box_sdf(p, [-2, -1, 2], [2, 1, 8]))

    v, f, labels = _semantic_mesh(sdf, [-4, -3, -1], [4, 3, 11], (3.0, 6.0), 0.1)
    seen = measure_semantic_mesh(v, f, labels)
    assert seen.facade_area_m2 == pytest.approx(200.0, rel=0.01)
    assert seen.wwr == pytest.approx(0.3, abs=0.01)
    assert seen.ungrouped_facade_area_m2 < 1.0
    every = measure_semantic_mesh(v, f, labels, config=MeasureConfig(
        stages=MeasureStages(visibility_cull=False)))
    assert every.facade_area_m2 > seen.facade_area_m2 + 0.9 * 72.0


def test_mesh_without_facade_classes_has_no_wwr():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]])
    m = measure_semantic_mesh(v, [[0, 1, 2]], np.full(3, ROOF))
    assert m.wwr is None and m.facade_area_m2 == 0 and m.facades == ()


@pytest.mark.parametrize("labels, faces, message", [
    (np.zeros(2), [[0, 1, 2]], "vertex_labels must have shape"),
    (np.full(3, 9), [[0, 1, 2]], "class ids outside"),
    (np.zeros(3), [[0, 1, 3]], "do not exist"),
    (np.zeros(3), [[0, 1]], r"shape \(F, 3\)"),
])
def test_bad_inputs(labels, faces, message):
    with pytest.raises(ValueError, match=message):
        measure_semantic_mesh(np.zeros((3, 3)), faces, labels)


@pytest.mark.parametrize("kwargs", [
    {"facade_max_tilt_deg": 90.0}, {"azimuth_bin_deg": 0.0},
    {"min_facade_separation_deg": 0.0}, {"plane_gap_m": -1.0}, {"plane_slab_m": -0.1},
    {"plane_max_angle_deg": 90.0}, {"curve_strip_m": 0.0}, {"visibility_rays_per_sample": 0},
    {"min_escape_fraction": 0.0},
])
def test_bad_config(kwargs):
    with pytest.raises(ValueError, match=next(iter(kwargs))):
        MeasureConfig(**kwargs)
