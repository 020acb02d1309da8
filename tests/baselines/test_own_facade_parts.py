"""The parts of the own-facade 2D methods on closed-form facades: planes in one view, planes
merged across views, areas by cell voting (baselines.view_planes, plane_merge, facade_cells)."""

from __future__ import annotations

import numpy as np
import pytest
from baselines_synthetic import facade_pose, render_facade, window_grid

from baselines.facade_cells import CellConfig, measure_facade_cells
from baselines.plane_merge import MergeConfig, facade_plane, merge_view_planes, same_facade
from baselines.posed_views import PosedView
from baselines.view_planes import UP, PlaneFitConfig, ViewPlane, find_view_planes
from envelope.camera import Intrinsics, look_at
from envelope.scene_record import Frame

K = Intrinsics.from_fov(160, 120, 60.0)
L_M, H_M = 10.0, 6.0  # the synthetic facade: y = 0, x in [0, L], z in [0, H], facing -y
WINDOWS = window_grid(L_M, H_M, cols=3, rows=2, width_m=1.2, win_height_m=1.4)
WINDOW_M2 = sum((x1 - x0) * (z1 - z0) for x0, z0, x1, z1 in WINDOWS)


def _view(index: int, pose: np.ndarray, **facade) -> PosedView:
    labels, depth = render_facade(K, pose, length_m=L_M, height_m=H_M, windows=WINDOWS, **facade)
    return PosedView("synthetic", index, Frame(f"images/{index}.png", pose, K, "train"), labels,
                     depth.astype(np.float32))


def _plane(view_index: int, normal, offset_m: float, s0: float, s1: float) -> ViewPlane:
    """A view plane whose inliers are a 20 x 5 grid over s in [s0, s1], z in [0, 6]."""
    n = np.array([*normal, 0.0], dtype=np.float64) / np.linalg.norm(normal)
    along = np.cross(UP, n)
    s, z = np.meshgrid(np.linspace(s0, s1, 20), np.linspace(0.0, 6.0, 5))
    points = n * offset_m + s.reshape(-1, 1) * along + z.reshape(-1, 1) * UP
    return ViewPlane(view_index, n, offset_m, (s0, s1), (0.0, 6.0), points, len(points))


def test_one_view_finds_the_facade_and_its_side_wall_with_their_outward_normals():
    # A camera 40 degrees off the facade towards +x sees the facade (normal -y, plane y = 0)
    # and the side wall at x = L (normal +x, 4 m deep).
    view = _view(0, facade_pose(L_M, H_M, distance_m=18.0, azimuth_deg=40.0), neighbour_m=4.0)
    planes = find_view_planes(view, PlaneFitConfig(), np.random.default_rng(0))
    assert len(planes) == 2
    front, side = planes  # largest first: the facade fills more of the photo
    assert np.degrees(np.arccos(front.normal @ [0, -1, 0])) < 1.0
    assert np.degrees(np.arccos(side.normal @ [1, 0, 0])) < 1.0
    assert front.offset_m == pytest.approx(0.0, abs=0.02)  # -y . x = 0
    assert side.offset_m == pytest.approx(L_M, abs=0.02)  # +x . x = L
    # along = up x normal = +x for the facade: its inliers span x in [0, L]
    assert front.s_range_m == pytest.approx((0.0, L_M), abs=0.2)
    assert front.z_range_m == pytest.approx((0.0, H_M), abs=0.2)


def test_a_view_showing_no_facade_pixel_has_no_plane():
    nothing = _view(0, facade_pose(L_M, H_M, distance_m=18.0, azimuth_deg=0.0))
    nothing = PosedView("synthetic", 0, nothing.frame, np.zeros_like(nothing.labels),
                        nothing.depth_z_m)
    assert find_view_planes(nothing, PlaneFitConfig(), np.random.default_rng(0)) == []


def test_planes_merge_when_normal_offset_and_extent_agree():
    config = MergeConfig(angle_deg=10.0, offset_m=0.5, gap_m=1.0)
    a = _plane(0, (0, -1), 0.0, 0.0, 10.0)
    assert same_facade(a, _plane(1, (0, -1), 0.3, 9.0, 15.0), config)  # overlapping, 0.3 m
    assert same_facade(a, _plane(1, (0, -1), 0.0, 10.9, 15.0), config)  # 0.9 m gap
    assert not same_facade(a, _plane(1, (0, -1), 0.0, 11.1, 15.0), config)  # 1.1 m gap
    assert not same_facade(a, _plane(1, (0, -1), 0.7, 0.0, 10.0), config)  # 0.7 m behind
    tilted = (np.sin(np.radians(12)), -np.cos(np.radians(12)))
    assert not same_facade(a, _plane(1, tilted, 0.0, 0.0, 10.0), config)  # 12 degrees
    assert not same_facade(a, _plane(1, (0, 1), 0.0, -10.0, 0.0), config)  # facing away


def test_merged_facades_are_one_per_wall_with_the_union_of_their_extents():
    # Two views see the wall y = 0 in parts that touch, a third a parallel wall 3 m behind it.
    planes = [_plane(0, (0, -1), 0.0, 0.0, 6.0), _plane(1, (0, -1), 0.05, 5.5, 12.0),
              _plane(1, (0, -1), -3.0, 0.0, 12.0)]
    facades = merge_view_planes(planes, MergeConfig())
    assert len(facades) == 2
    wall, behind = facades
    assert wall.view_indices == {0, 1} and behind.view_indices == {1}
    assert wall.s_range_m == pytest.approx((0.0, 12.0), abs=0.06)
    assert wall.offset_m == pytest.approx(0.025, abs=0.03)
    assert behind.offset_m == pytest.approx(-3.0)
    np.testing.assert_allclose(wall.normal, [0, -1, 0], atol=1e-9)
    np.testing.assert_allclose(facade_plane([planes[2]]).centre_m, [6.0, 3.0, 3.0], atol=1e-9)


def _facade_on_y0() -> object:
    return facade_plane([_plane(0, (0, -1), 0.0, 0.0, L_M)])  # exact plane y = 0, x in [0, L]


@pytest.mark.parametrize("recess_m", [0.0, 0.3])
def test_cell_voting_measures_the_facade_once_however_many_views_see_it(recess_m):
    # Three views of the whole facade: the areas are the facade's, not three times them.
    # A cell's class is read at its centre: an edge is off by at most a cell or a pixel's
    # footprint (about 0.1 m here), so each area is within its outline's length x 0.1 m.
    views = [_view(i, facade_pose(L_M, H_M, distance_m=16.0, azimuth_deg=a), recess_m=recess_m)
             for i, a in enumerate((-25.0, 0.0, 25.0))]
    cells = measure_facade_cells(_facade_on_y0(), views, CellConfig(cell_m=0.1))
    assert cells is not None and cells.views == 3
    outline_m = 2 * (L_M + H_M)
    window_outline_m = sum(2 * (x1 - x0 + z1 - z0) for x0, z0, x1, z1 in WINDOWS)
    assert cells.areas.gross_m2 == pytest.approx(L_M * H_M, abs=0.1 * outline_m)
    assert cells.areas.window_m2 == pytest.approx(WINDOW_M2, abs=0.1 * window_outline_m)
    assert cells.areas.door_m2 == 0.0
    assert cells.width_m == pytest.approx(L_M, abs=0.2)
    assert cells.height_m == pytest.approx(H_M, abs=0.2)
    np.testing.assert_allclose(cells.centre_m, [L_M / 2, 0.0, H_M / 2], atol=0.1)


def test_cells_hidden_from_every_view_or_seen_from_behind_are_not_counted():
    # Balconies 1.2 m in front hide a band; a camera behind the facade votes nothing.
    band = (2.0, 3.0)
    front = _view(0, facade_pose(L_M, H_M, distance_m=16.0, azimuth_deg=0.0), balconies=[band])
    behind_pose = look_at([L_M / 2, 16.0, 1.6], [L_M / 2, 0.0, H_M / 2])
    behind = PosedView("synthetic", 1, Frame("images/1.png", behind_pose, K, "train"),
                       front.labels, front.depth_z_m)  # its images do not matter
    alone = measure_facade_cells(_facade_on_y0(), [front], CellConfig())
    both = measure_facade_cells(_facade_on_y0(), [front, behind], CellConfig())
    assert alone is not None and both is not None
    assert both.areas == alone.areas and both.views == 1
    # The camera at eye height sees over nothing: the band behind the balcony (1 m of
    # height; a little more, foreshortened from below) is missing from the facade.
    assert L_M * H_M - alone.areas.gross_m2 == pytest.approx(L_M * (band[1] - band[0]), rel=0.3)
