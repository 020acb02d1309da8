"""neural3d.extraction.footprint: zero contour of analytic SDFs on a horizontal plane."""

import numpy as np
import pytest
from sdf_shapes import box_sdf, cylinder_sdf, l_prism_sdf
from shapely.geometry import MultiPolygon, Point, Polygon
from shapely.geometry import box as rectangle

from envelope.footprint import geojson_to_polygon, polygon_to_geojson
from neural3d.extraction.footprint import footprint_from_sdf

SCENE_LO, SCENE_HI = np.array([-2.0, -2.0, -1.0]), np.array([14.0, 14.0, 10.0])


def _iou(a, b) -> float:
    return a.intersection(b).area / a.union(b).area


def _footprint(sdf, **kwargs):
    args = {"heights_m": (0.5,), "cell_m": 0.1, "min_area_m2": 1.0, **kwargs}
    return footprint_from_sdf(sdf, SCENE_LO, SCENE_HI, **args)


def test_l_prism_footprint():
    truth = rectangle(0, 0, 10, 4).union(rectangle(0, 0, 4, 12))
    poly = _footprint(l_prism_sdf)
    assert isinstance(poly, Polygon) and poly.is_valid
    assert _iou(poly, truth) >= 0.99
    assert poly.area == pytest.approx(72.0, rel=0.01)
    # the GeoJSON round trip the extract CLI writes
    assert _iou(geojson_to_polygon(polygon_to_geojson(poly)), poly) == pytest.approx(1, abs=1e-9)


def test_circle_area_and_cell_size():
    coarse = _footprint(lambda p: cylinder_sdf(p, [6, 6], 5.0, 0, 8), cell_m=0.5)
    fine = _footprint(lambda p: cylinder_sdf(p, [6, 6], 5.0, 0, 8), cell_m=0.05)
    circle = Point(6, 6).buffer(5.0, 256)
    # linear interpolation between samples cuts the convex curve: always a little inside
    assert fine.area <= np.pi * 25 and fine.area == pytest.approx(np.pi * 25, rel=1e-3)
    assert _iou(fine, circle) > _iou(coarse, circle) > 0.99


def test_courtyard_is_a_hole():
    def sdf(p):  # 12 x 12 m block with a 4 x 4 m courtyard cut out
        return np.maximum(box_sdf(p, [0, 0, 0], [12, 12, 8]), -box_sdf(p, [4, 4, -1], [8, 8, 9]))

    poly = _footprint(sdf)
    assert isinstance(poly, Polygon) and len(poly.interiors) == 1
    assert Polygon(poly.interiors[0]).area == pytest.approx(16.0, rel=0.01)
    assert poly.area == pytest.approx(144 - 16, rel=0.01)
    # a hole below min_area_m2 is filled
    assert len(_footprint(sdf, min_area_m2=20.0).interiors) == 0


def test_roofed_pocket_is_filled_and_courtyard_kept():
    # a trained field may leave an empty pocket inside the building (no camera sees it):
    # a 4 x 4 x 3 m void under the roof of a 12 x 12 x 8 m block is no courtyard
    def pocket(p):
        return np.maximum(box_sdf(p, [0, 0, 0], [12, 12, 8]), -box_sdf(p, [4, 4, 0.2], [8, 8, 3]))

    def courtyard_and_pocket(p):  # a courtyard open to the sky beside the pocket
        return np.maximum(pocket(p), -box_sdf(p, [1, 8.5, -1], [3, 10.5, 9]))

    filled = _footprint(pocket)
    assert isinstance(filled, Polygon) and len(filled.interiors) == 0
    assert filled.area == pytest.approx(144, rel=0.01)
    kept = _footprint(courtyard_and_pocket)
    assert len(kept.interiors) == 1
    assert Polygon(kept.interiors[0]).area == pytest.approx(4.0, rel=0.02)
    assert kept.area == pytest.approx(144 - 4, rel=0.01)


def test_a_pillar_in_a_filled_pocket_merges_into_the_footprint():
    """The contour cuts the pocket as a hole and the pillar standing in it as a piece of its
    own; once the roofed pocket is filled, the pillar lies inside the footprint: one valid
    polygon, not two overlapping pieces."""
    def pocket_with_pillar(p):
        walls = np.maximum(box_sdf(p, [0, 0, 0], [12, 12, 8]),
                           -box_sdf(p, [3, 3, 0.2], [9, 9, 3]))
        return np.minimum(walls, box_sdf(p, [5, 5, 0], [7, 7, 8]))

    poly = _footprint(pocket_with_pillar)
    assert isinstance(poly, Polygon) and poly.is_valid and len(poly.interiors) == 0
    assert poly.area == pytest.approx(144, rel=0.01)
    unfilled = _footprint(pocket_with_pillar, roofed_hole_fill=False)
    assert isinstance(unfilled, MultiPolygon) and len(unfilled.geoms) == 2
    assert unfilled.area == pytest.approx(144 - 36 + 4, rel=0.01)


def test_separate_pieces_and_slivers():
    def sdf(p):
        return np.minimum.reduce([box_sdf(p, [0, 0, 0], [4, 4, 8]),
                                  box_sdf(p, [8, 8, 0], [12, 12, 8]),
                                  box_sdf(p, [10, 0, 0], [10.5, 0.5, 8])])  # 0.25 m² piece

    poly = _footprint(sdf)
    assert isinstance(poly, MultiPolygon) and len(poly.geoms) == 2
    assert poly.area == pytest.approx(32.0, rel=0.01)
    assert len(_footprint(sdf, min_area_m2=0.1).geoms) == 3


def test_plane_that_misses_the_building():
    with pytest.raises(ValueError, match="miss the building"):
        _footprint(l_prism_sdf, heights_m=(9.0,))  # above the 8 m roof
    with pytest.raises(ValueError, match="outside the box"):
        _footprint(l_prism_sdf, heights_m=(1.0, 12.0))
    with pytest.raises(ValueError, match="at least one"):
        _footprint(l_prism_sdf, heights_m=())
    with pytest.raises(ValueError, match="wholly inside"):
        _footprint(lambda p: np.full(len(p), -1.0))
    with pytest.raises(ValueError, match="no footprint piece"):
        _footprint(l_prism_sdf, min_area_m2=100.0)


def test_averaging_planes_cancels_wobbles_of_the_walls():
    """A 10 x 6 m box whose walls sit +-0.15 m off, alternating with height, on the planes.

    On each plane alone the footprint is 0.3 m too wide or too narrow; the SDF
    averaged over the four planes puts every wall back where it is.
    """
    truth = rectangle(0, 0, 10, 6)

    def wobbly(p):
        offset = np.where(np.floor(p[:, 2] / 0.5) % 2 == 0, 0.15, -0.15)  # 1.0, 2.0: +0.15
        return box_sdf(p, [0, 0, 0], [10, 6, 8]) - offset

    one = _footprint(wobbly, heights_m=(1.0,))
    assert one.area == pytest.approx(10.3 * 6.3, rel=1e-3)
    band = _footprint(wobbly, heights_m=(1.0, 1.5, 2.0, 2.5))
    assert _iou(band, truth) >= 0.995 > 0.97 > _iou(one, truth)


def _overhang_sdf(p):
    # ground floor 10 x 6 m up to 2.7 m (the lowest first floor); the floors above reach
    # 1.5 m further out at the front (y < 0) and 1 m at the east end, up to 12 m
    return np.minimum(box_sdf(p, [0, 0, 0], [10, 6, 2.7]), box_sdf(p, [0, -1.5, 2.7], [11, 6, 12]))


def test_the_ground_floor_planes_give_the_ground_outline_under_an_overhang():
    from neural3d.extraction.extract_config import (
        GROUND_FLOOR_HEIGHTS_M,
        ExtractConfig,
        footprint_heights_m,
    )

    config = ExtractConfig(footprint_heights_m=GROUND_FLOOR_HEIGHTS_M)
    heights = footprint_heights_m(np.array([12.0, 8.0, 13.0]), config)
    ground = _footprint(_overhang_sdf, heights_m=heights)
    truth = rectangle(0, 0, 10, 6)
    assert _iou(ground, truth) >= 0.995
    assert ground.area == pytest.approx(60.0, rel=0.005)
    # the default planes (1-4 m) take part of the overhang into the outline
    default = _footprint(_overhang_sdf, heights_m=ExtractConfig().footprint_heights_m)
    assert _iou(default, truth) < 0.97


def test_widest_outline_is_the_union_of_the_storeys():
    from neural3d.extraction.footprint import widest_outline_from_sdf

    widest = widest_outline_from_sdf(_overhang_sdf, SCENE_LO, SCENE_HI, from_height_m=1.0,
                                     step_m=0.5, cell_m=0.1, min_area_m2=1.0)
    truth = rectangle(0, -1.5, 11, 6)
    assert _iou(widest, truth) >= 0.995
    assert widest.area == pytest.approx(11 * 7.5, rel=0.005)
    with pytest.raises(ValueError, match="step_m"):
        widest_outline_from_sdf(_overhang_sdf, SCENE_LO, SCENE_HI, from_height_m=1.0,
                                step_m=0.0, cell_m=0.1, min_area_m2=1.0)


def test_extract_keeps_footprint_planes_below_half_the_box():
    from neural3d.extraction.extract_config import ExtractConfig, footprint_heights_m

    config = ExtractConfig()
    assert footprint_heights_m(np.array([5.0, 5.0, 20.0]), config) == config.footprint_heights_m
    assert footprint_heights_m(np.array([5.0, 5.0, 4.0]), config) == (1.0, 1.5, 2.0)
    assert footprint_heights_m(np.array([5.0, 5.0, 1.0]), config) == (1.0,)  # the lowest stays
    with pytest.raises(ValueError, match="footprint_heights_m"):
        ExtractConfig(footprint_heights_m=())


@pytest.mark.parametrize("kwargs, message", [
    ({"cell_m": 0.0}, "cell_m"),
    ({"cell_m": 1e-3}, "too large"),
    ({"min_area_m2": -1.0}, "min_area_m2"),
])
def test_bad_arguments(kwargs, message):
    with pytest.raises(ValueError, match=message):
        _footprint(l_prism_sdf, **kwargs)
