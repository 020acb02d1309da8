"""Straight walls: a wobbly, round-cornered contour of a rectangle becomes the rectangle;
curves stay within the tolerance of themselves; holes, pieces and bad settings."""

from __future__ import annotations

import numpy as np
import pytest
from shapely.geometry import MultiPolygon, Point, Polygon, box

from neural3d.extraction.extract_config import STAGES, ExtractConfig, without_stages
from neural3d.extraction.straight_walls import douglas_peucker_indices, straighten_footprint

TOLERANCE_M, MIN_WALL_M = 0.15, 1.0


def iou(a, b) -> float:
    return a.intersection(b).area / a.union(b).area


def wobbly_rectangle(width_m: float, depth_m: float, *, wobble_m: float, corner_m: float,
                     step_m: float = 0.02, centre=(0.0, 0.0)) -> Polygon:
    """The rectangle's outline with rounded corners (radius ``corner_m``), pushed in and out
    along its normal by a zero-mean sine of amplitude ``wobble_m`` (period 1.3 m): what a
    trained field's contour does to a straight wall."""
    rounded = box(-width_m / 2 + corner_m, -depth_m / 2 + corner_m, width_m / 2 - corner_m,
                  depth_m / 2 - corner_m).buffer(corner_m, quad_segs=16)
    ring = rounded.exterior.segmentize(step_m)
    xy = np.asarray(ring.coords)[:-1]
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(xy, axis=0), axis=1))])
    tangent = np.gradient(xy, axis=0)
    normal = np.column_stack([tangent[:, 1], -tangent[:, 0]])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    xy = xy + wobble_m * np.sin(2 * np.pi * s / 1.3)[:, None] * normal
    return Polygon(xy + np.asarray(centre))


def test_a_wobbly_round_cornered_rectangle_becomes_the_rectangle():
    """Wobble +-3 cm, corners rounded to 0.2 m: the four walls' lines meet at the corners."""
    truth = box(-5.0, -3.0, 5.0, 3.0)
    contour = wobbly_rectangle(10.0, 6.0, wobble_m=0.03, corner_m=0.2)
    straight = straighten_footprint(contour, tolerance_m=TOLERANCE_M, min_wall_m=MIN_WALL_M)
    assert iou(contour, truth) < 0.99  # the wobble and the rounded corners cost 1 %
    assert iou(straight, truth) > 0.998
    corners = np.asarray(straight.exterior.coords)[:-1]
    assert len(corners) == 4
    assert straight.hausdorff_distance(truth) < 0.02


def test_a_corner_rounded_beyond_the_tolerance_keeps_part_of_its_rounding():
    """Corners rounded to 0.5 m stray r (sqrt 2 - 1) = 0.21 m from the sharp corner, more
    than the tolerance: the simplification cuts a short run there, which keeps its points.
    The walls are still straightened: the IoU rises from 0.987 to above 0.995."""
    truth = box(-5.0, -3.0, 5.0, 3.0)
    contour = wobbly_rectangle(10.0, 6.0, wobble_m=0.03, corner_m=0.5)
    straight = straighten_footprint(contour, tolerance_m=TOLERANCE_M, min_wall_m=MIN_WALL_M)
    assert iou(contour, truth) < 0.988
    assert iou(straight, truth) > 0.995
    assert 0.15 < straight.hausdorff_distance(truth) < 0.5 * (np.sqrt(2) - 1) + 0.03


def test_a_circle_stays_within_the_tolerance_of_itself():
    """A curve becomes a polygon whose sides stray at most about the tolerance from it:
    radius 5 m, tolerance 0.15 m; the IoU with the circle stays above 0.99."""
    circle = Point(0.0, 0.0).buffer(5.0, quad_segs=256)
    straight = straighten_footprint(circle, tolerance_m=TOLERANCE_M, min_wall_m=MIN_WALL_M)
    assert iou(straight, circle) > 0.99
    radii = np.linalg.norm(np.asarray(straight.exterior.coords), axis=1)
    assert np.all(np.abs(radii - 5.0) < TOLERANCE_M)


def test_short_runs_keep_their_points():
    """A contour whose every straight run is shorter than min_wall_m is left as it is."""
    small = wobbly_rectangle(0.8, 0.6, wobble_m=0.01, corner_m=0.1)
    straight = straighten_footprint(small, tolerance_m=TOLERANCE_M, min_wall_m=MIN_WALL_M)
    assert straight.equals(small)


def test_a_courtyard_and_a_second_piece_are_straightened_too():
    outer = wobbly_rectangle(20.0, 16.0, wobble_m=0.05, corner_m=0.3)
    court = wobbly_rectangle(8.0, 6.0, wobble_m=0.05, corner_m=0.3)
    annex = wobbly_rectangle(4.0, 4.0, wobble_m=0.05, corner_m=0.3, centre=(20.0, 0.0))
    contour = MultiPolygon([Polygon(outer.exterior, [court.exterior]), annex])
    truth = MultiPolygon([Polygon(box(-10, -8, 10, 8).exterior, [box(-4, -3, 4, 3).exterior]),
                          box(18, -2, 22, 2)])
    straight = straighten_footprint(contour, tolerance_m=TOLERANCE_M, min_wall_m=MIN_WALL_M)
    assert isinstance(straight, MultiPolygon) and len(straight.geoms) == 2
    assert all(len(p.interiors) == n for p, n in zip(straight.geoms, (1, 0)))
    assert iou(straight, truth) > 0.998 > iou(contour, truth)
    assert straight.is_valid


def test_a_rotated_l_shape_keeps_its_six_corners():
    l_shape = Polygon([(0, 0), (12, 0), (12, 5), (5, 5), (5, 10), (0, 10)])
    angle = np.radians(27.0)
    rot = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    truth = Polygon(np.asarray(l_shape.exterior.coords) @ rot.T)
    # the contour: the outline densely sampled and wobbled by +-4 cm
    ring = np.asarray(truth.exterior.segmentize(0.02).coords)[:-1]
    rng = np.random.default_rng(0)
    contour = Polygon(ring + rng.normal(0.0, 0.02, ring.shape).clip(-0.04, 0.04))
    straight = straighten_footprint(contour, tolerance_m=TOLERANCE_M, min_wall_m=MIN_WALL_M)
    assert len(straight.exterior.coords) - 1 == 6
    assert iou(straight, truth) > 0.999


def test_douglas_peucker_keeps_the_ends_and_the_far_points():
    # (1, 0.5) lies on the chord from (0, 0) to (2, 1); (3, 0.52) is 0.02 * 2 / sqrt(5) =
    # 0.0179 m from the chord from (2, 1) to (4, 0); (2, 1) is 1 m from the whole chord
    points = np.array([[0.0, 0.0], [1.0, 0.5], [2.0, 1.0], [3.0, 0.52], [4.0, 0.0]])
    assert douglas_peucker_indices(points, 0.1).tolist() == [0, 2, 4]
    assert douglas_peucker_indices(points, 2.0).tolist() == [0, 4]
    assert douglas_peucker_indices(points, 0.01).tolist() == [0, 2, 3, 4]


@pytest.mark.parametrize("tolerance_m, min_wall_m", [(0.0, 1.0), (0.15, 0.0), (-1.0, 1.0)])
def test_settings_must_be_positive(tolerance_m, min_wall_m):
    with pytest.raises(ValueError, match="must be > 0"):
        straighten_footprint(box(0, 0, 5, 5), tolerance_m=tolerance_m, min_wall_m=min_wall_m)
    with pytest.raises(ValueError, match="must be > 0"):
        ExtractConfig(footprint_wall_tolerance_m=tolerance_m, footprint_min_wall_m=min_wall_m)


def test_the_stage_is_the_footprints_last_and_can_be_switched_off():
    assert STAGES[-2:] == ("roofed_hole_fill", "straight_walls")
    assert ExtractConfig().straight_walls
    off = without_stages(ExtractConfig(), "straight_walls")
    assert not off.straight_walls and off.roofed_hole_fill
    assert off.measure == ExtractConfig().measure
