"""A wall with openings: frame maths, face areas against closed forms, grids, bad input."""

import numpy as np
import pytest

from dataset.families.facade_geometry import (
    MIN_GAP_M,
    Opening,
    WallFrame,
    WallSpec,
    drop_near,
    rectangle_outline,
    wall_faces,
    window_grid,
)
from dataset.families.polygon_mesh import triangulate_faces
from envelope.classes import NO_FACADE, SemanticClass


def test_frame_reproduces_its_end_points_exactly_and_faces_right():
    frame = WallFrame((0.1, 0.7), (-2.3, 5.9))
    ends = frame.points_m(np.array([[0.0, 0.0], [frame.length_m, 3.0]]))
    assert tuple(ends[0, :2]) == (0.1, 0.7) and tuple(ends[1, :2]) == (-2.3, 5.9)
    assert ends[1, 2] == 3.0
    d = np.array([-2.4, 5.2]) / np.hypot(2.4, 5.2)
    np.testing.assert_allclose(frame.normal, [d[1], -d[0], 0], atol=1e-15)
    out = frame.points_m(np.array([[1.0, 2.0, 0.5]]))[0]
    np.testing.assert_allclose(out, [*(np.array([0.1, 0.7]) + d + 0.5 * frame.normal[:2]), 2.0])


def _wall(openings=(), contacts=()):
    frame = WallFrame((0.0, 0.0), (6.0, 0.0))  # faces -y
    return WallSpec(frame, 1, rectangle_outline(6.0, 3.0), tuple(openings), tuple(contacts))


def test_wall_faces_have_the_closed_form_areas():
    win = Opening("window", 1.0, 1.0, 2.5, 2.2, depth_m=0.07)
    door = Opening("door", 4.0, 0.1, 5.0, 2.3, depth_m=0.08)
    spec = _wall([win, door], [(0.2, 2.5, 0.9, 2.8)])
    assert spec.gross_area_m2() == pytest.approx(18.0)
    assert spec.wall_area_m2() == pytest.approx(18.0 - 1.8 - 2.2 - 0.21)
    mesh = triangulate_faces(wall_faces(spec))
    areas = mesh.face_areas_m2()
    on_facade = mesh.face_facade == 1
    wall = on_facade & (mesh.face_label == SemanticClass.WALL)
    assert areas[wall].sum() == pytest.approx(spec.wall_area_m2(), rel=1e-12)
    pane = on_facade & (mesh.face_label == SemanticClass.WINDOW)
    assert areas[pane].sum() == pytest.approx(1.8, rel=1e-12)
    assert areas[on_facade & (mesh.face_label == SemanticClass.DOOR)].sum() == pytest.approx(2.2)
    reveal = mesh.face_facade == NO_FACADE
    # Reveals: perimeter x depth, labelled with their opening's class.
    assert areas[reveal & (mesh.face_label == SemanticClass.WINDOW)].sum() == pytest.approx(
        2 * (1.5 + 1.2) * 0.07, rel=1e-12)
    assert areas[reveal & (mesh.face_label == SemanticClass.DOOR)].sum() == pytest.approx(
        2 * (1.0 + 2.2) * 0.08, rel=1e-12)
    # Panes sit behind the facade plane (y = 0, outward -y) by their reveal depth.
    pane_y = mesh.triangles_m[pane][..., 1]
    np.testing.assert_allclose(pane_y, 0.07, atol=1e-12)
    normals = mesh.face_normals()
    np.testing.assert_allclose(normals[on_facade], np.tile([0, -1, 0], (on_facade.sum(), 1)),
                               atol=1e-12)


def test_window_grid_positions_and_counts():
    grid = window_grid(10.0, 3, 3.0, columns=4, window_width_m=1.0, window_height_m=1.5,
                       sill_height_m=0.8, margin_m=1.0, depth_m=0.06, first_floor=1)
    assert len(grid) == 2 * 4
    centres = sorted({(o.u0_m + o.u1_m) / 2 for o in grid})
    np.testing.assert_allclose(centres, [2.0, 4.0, 6.0, 8.0])
    assert sorted({o.v0_m for o in grid}) == pytest.approx([3.8, 6.8])
    assert all(o.area_m2 == pytest.approx(1.5) for o in grid)


def test_drop_near_keeps_only_clear_windows():
    door = Opening("door", 4.6, 0.1, 5.4, 2.2)
    grid = window_grid(10.0, 1, 3.0, columns=4, window_width_m=1.0, window_height_m=1.5,
                       sill_height_m=0.8, margin_m=1.0, depth_m=0.06)
    assert len(drop_near(grid, [door])) == 4  # 0.1 m from the windows at 3.5-4.5 and 5.5-6.5
    wide = Opening("door", 3.3, 0.1, 6.7, 2.2)
    assert len(drop_near(grid, [wide])) == 2


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"floors": 0}, "floors, columns >= 1"),
        ({"columns": 6}, "do not fit"),
        ({"window_height_m": 2.5}, "exceed the floor height"),
        ({"margin_m": -1.0}, "margin must be >= 0"),
    ],
)
def test_window_grid_rejects_grids_that_do_not_fit(kwargs, message):
    args = dict(floors=2, columns=4, window_width_m=1.2, window_height_m=1.4,
                sill_height_m=0.9, margin_m=0.8, depth_m=0.06)
    args.update(kwargs)
    floors = args.pop("floors")
    with pytest.raises(ValueError, match=message):
        window_grid(8.0, floors, 3.0, **args)


def test_bad_openings_raise_helpful_errors():
    with pytest.raises(ValueError, match="has no area"):
        Opening("window", 2.0, 1.0, 1.0, 2.0)
    with pytest.raises(ValueError, match="kind must be"):
        Opening("skylight", 0, 0, 1, 1)
    with pytest.raises(ValueError, match="reveal depth"):
        Opening("window", 0, 0, 1, 1, depth_m=0.0)
    with pytest.raises(ValueError, match="does not fit"):
        _wall([Opening("window", 5.5, 1.0, 6.5, 2.0)])  # sticks out of the 6 m wall
    with pytest.raises(ValueError, match="does not fit"):
        _wall([Opening("window", 0.0, 1.0, 1.0, 2.0)])  # touches the edge: no margin
    with pytest.raises(ValueError, match="closer than"):
        _wall([Opening("window", 1, 1, 2, 2), Opening("window", 2 + MIN_GAP_M / 2, 1, 3, 2)])
    with pytest.raises(ValueError, match="closer than"):
        _wall([Opening("window", 1, 1, 2, 2)], [(1.5, 2.0, 2.5, 2.3)])
    with pytest.raises(ValueError, match="zero length"):
        WallFrame((1.0, 1.0), (1.0, 1.0))
    with pytest.raises(ValueError, match="spans u"):
        WallSpec(WallFrame((0.0, 0.0), (6.0, 0.0)), 1, rectangle_outline(5.0, 3.0))
    with pytest.raises(ValueError, match="facade id >= 1"):
        WallSpec(WallFrame((0.0, 0.0), (6.0, 0.0)), 0, rectangle_outline(6.0, 3.0))
