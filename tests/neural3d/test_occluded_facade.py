"""neural3d.extraction.occluded_facade: facade hidden behind a balcony, filled from its column.

The mesh is what a trained field gives at a balcony: a box building whose front wall
(y = 0, facing -y) has a window and, below it, a hole where the field never saw the wall,
with the balcony (class other) in front of the hole.
"""

from dataclasses import replace

import numpy as np
import pytest

from envelope.classes import SemanticClass
from neural3d.extraction.measure import measure_semantic_mesh
from neural3d.extraction.measure_config import MeasureConfig, MeasureStages

WALL, WINDOW, OTHER = int(SemanticClass.WALL), int(SemanticClass.WINDOW), int(SemanticClass.OTHER)
WIDTH_M, DEPTH_M, HEIGHT_M = 10.0, 8.0, 6.0
WINDOW_X_M, WINDOW_Z_M = (4.0, 6.0), (3.0, 5.0)
HOLE_X_M, HOLE_Z_M = (3.0, 7.0), (2.0, 3.0)


def _quad(corners, label):
    """Two triangles (unshared vertices) of a planar quad given counter-clockwise from outside."""
    v = np.array(corners, dtype=float)
    return v, np.array([[0, 1, 2], [0, 2, 3]]), np.full(4, label)


def _building(*, hole_z_m=HOLE_Z_M, balcony=True):
    """Box [0, W] x [0, D] x [0, H] in 1 m quads; the front wall (y = 0) has the window
    and the hole (no faces); a 4 x 0.3 x 1 m balcony box 1.2 m in front of the hole."""
    parts = []
    for x in range(int(WIDTH_M)):
        for z in range(int(HEIGHT_M)):
            cx, cz = x + 0.5, z + 0.5
            if HOLE_X_M[0] < cx < HOLE_X_M[1] and hole_z_m[0] < cz < hole_z_m[1]:
                continue
            window = WINDOW_X_M[0] < cx < WINDOW_X_M[1] and WINDOW_Z_M[0] < cz < WINDOW_Z_M[1]
            parts.append(_quad([(x, 0, z), (x + 1, 0, z), (x + 1, 0, z + 1), (x, 0, z + 1)],
                               WINDOW if window else WALL))
    w, d, h = WIDTH_M, DEPTH_M, HEIGHT_M
    parts += [
        _quad([(w, 0, 0), (w, d, 0), (w, d, h), (w, 0, h)], WALL),  # east
        _quad([(w, d, 0), (0, d, 0), (0, d, h), (w, d, h)], WALL),  # north
        _quad([(0, d, 0), (0, 0, 0), (0, 0, h), (0, d, h)], WALL),  # west
        _quad([(0, 0, h), (w, 0, h), (w, d, h), (0, d, h)], int(SemanticClass.ROOF)),
    ]
    if balcony:  # its front (facing -y) and top: what a camera in front sees of it
        (x0, x1), (z0, z1), y0, y1 = HOLE_X_M, HOLE_Z_M, -1.5, -1.2
        parts += [_quad([(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)], OTHER),
                  _quad([(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)], OTHER)]
    vertices, faces, labels, offset = [], [], [], 0
    for v, f, lab in parts:
        vertices.append(v)
        faces.append(f + offset)
        labels.append(lab)
        offset += len(v)
    return np.concatenate(vertices), np.concatenate(faces), np.concatenate(labels)


OFF = MeasureConfig(stages=MeasureStages().without("plane_probe"))


def _front(measurement):
    (front,) = [f for f in measurement.facades if round(f.azimuth_deg) % 360 == 270]
    return front


def test_hole_behind_a_balcony_takes_the_nearest_class_in_its_column():
    mesh = _building()
    before, after = measure_semantic_mesh(*mesh, config=OFF), measure_semantic_mesh(*mesh)
    # 4 x 1 m hole: under the window's 2 m the upper half continues the window (1 m²) and
    # the lower half the wall; beside it wall above and below (2 m²). Cells lie on the
    # metre edges (0.1 m grid from the wall's corner), so the split is exact.
    assert after.window_area_m2 - before.window_area_m2 == pytest.approx(1.0, abs=1e-9)
    assert after.wall_area_m2 - before.wall_area_m2 == pytest.approx(3.0, abs=1e-9)
    assert _front(after).window_area_m2 - _front(before).window_area_m2 == pytest.approx(1.0)
    assert _front(after).facade_area_m2 == pytest.approx(WIDTH_M * HEIGHT_M, abs=1e-9)
    assert before.facade_area_m2 == pytest.approx(2 * (WIDTH_M + DEPTH_M) * HEIGHT_M - 4.0)
    assert after.facade_area_m2 == pytest.approx(2 * (WIDTH_M + DEPTH_M) * HEIGHT_M)


def test_no_occluder_or_an_open_hole_adds_nothing():
    for mesh in (_building(balcony=False), _building(hole_z_m=(2.0, HEIGHT_M))):
        before, after = measure_semantic_mesh(*mesh, config=OFF), measure_semantic_mesh(*mesh)
        assert after.facade_area_m2 == pytest.approx(before.facade_area_m2, abs=1e-9)
        assert after.window_area_m2 == pytest.approx(before.window_area_m2, abs=1e-9)


def test_config_is_checked():
    with pytest.raises(ValueError, match="occluder_reach_m"):
        MeasureConfig(occluder_reach_m=0.2)
    with pytest.raises(ValueError, match="occlusion_cell_m"):
        MeasureConfig(occlusion_cell_m=-0.1)


def test_front_seen_faces_are_the_facade_a_camera_in_front_meets_first():
    """Every front-wall face is met first by some probe from in front; the balcony (class
    other), the roof and the faces of the other walls' planes (seen by their own probes
    only) are told apart by class and plane."""
    from envelope.geometry.raycast import Raycaster
    from neural3d.extraction.facade_groups import class_area_m2, group_faces
    from neural3d.extraction.facade_planes import project_onto_facade_planes
    from neural3d.extraction.occluded_facade import front_seen_faces, probe_planes

    v, f, lab = _building()
    config = MeasureConfig()
    shares = class_area_m2(v, f, lab)
    facade = shares[:, [WALL, WINDOW, int(SemanticClass.DOOR)]].sum(axis=1)
    planes = project_onto_facade_planes(v, f, facade, group_faces(v, f, facade, config),
                                        config=config)
    probes = probe_planes(Raycaster.from_triangles(v, f), shares, planes, cell_m=0.1,
                          slab_m=config.plane_slab_m, max_angle_deg=config.plane_max_angle_deg)
    seen = front_seen_faces(probes, len(f))
    facade_faces = facade > 0
    assert seen[facade_faces].all() and not seen[~facade_faces].any()
    (front,) = np.flatnonzero(np.round(planes.azimuth_deg) % 360 == 270)
    probe = probes[front]
    assert probe.shape == (100, 60) and probe.seen.sum() == 6000 - 400  # the hole's 4 m²


@pytest.mark.slow
def test_faces_the_hemisphere_test_drops_but_the_front_sees_count():
    """Square slot windows (0.4 m, recessed 0.38 m) in a box (tests/neural3d/test_measure.py): few
    hemisphere rays leave a slot, and the test drops part of the panes and reveals (window
    1.02 m² measured; 1.59 m² without the test, 1.28 m² true); seen from in front they
    count again, never more than without the test. (A wide recess keeps its pane: its
    downward rays leave the building's x/y box before they meet the ground.)"""
    from test_measure import _recessed_box

    v, f, lab = _recessed_box(window_m=(0.4, 0.4), depth_m=0.38)
    truth_m2 = 8 * 0.4 * 0.4
    dropped = measure_semantic_mesh(v, f, lab, config=OFF)
    counted = measure_semantic_mesh(v, f, lab)
    every = measure_semantic_mesh(v, f, lab, config=replace(
        OFF, stages=OFF.stages.without("visibility_cull")))
    assert dropped.window_area_m2 < counted.window_area_m2 <= every.window_area_m2 + 1e-9
    assert abs(counted.window_area_m2 - truth_m2) < abs(dropped.window_area_m2 - truth_m2)
