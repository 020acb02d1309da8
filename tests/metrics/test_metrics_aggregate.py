"""Aggregation per family: mean ± population std, counts, failures, pooled rows, order."""

import math

import pytest

from metrics.score.aggregate import ALL_FAMILIES, Summary, aggregate_by_family, summarise
from metrics.score.errors import BuildingErrors, failed_building


def _row(scene, family, method, protocol, wwr_ape, iou=None):
    return BuildingErrors(scene, family, method, protocol, wwr_ape=wwr_ape, window_ape=wwr_ape,
                          facade_ape=0.0, footprint_iou=iou)


def test_summarise_hand_computed():
    s = summarise([20.0, 10.0, None])
    assert (s.mean, s.std, s.count) == pytest.approx((15.0, 5.0, 2), abs=1e-12)
    s = summarise([1.0, 2.0, 3.0, 4.0])
    assert s.std == pytest.approx(math.sqrt(1.25), abs=1e-12)  # population std, ddof = 0
    assert summarise([7.0]) == Summary(7.0, 0.0, 1)
    assert summarise([None, None]) == Summary(None, None, 0)


def test_summarise_rejects_nan():
    with pytest.raises(ValueError, match="use None for a missing one"):
        summarise([1.0, math.nan])


def test_aggregate_groups_failures_and_pooled_rows():
    rows = [
        _row("a", "skyscraper", "2D-S", "ideal", 20.0),
        _row("b", "skyscraper", "2D-S", "ideal", 10.0),
        failed_building("c", "skyscraper", "2D-S", "ideal", "no views"),
        _row("d", "l_shaped", "2D-S", "ideal", 0.0),
        _row("a", "skyscraper", "neural3d", "train", 5.0, iou=0.5),
        _row("d", "l_shaped", "2D-S", "multi", 30.0),
    ]
    groups = aggregate_by_family(rows)
    keys = [(g.family, g.method, g.protocol) for g in groups]
    assert keys == [
        ("skyscraper", "2D-S", "ideal"), ("skyscraper", "neural3d", "train"),
        ("l_shaped", "2D-S", "ideal"), ("l_shaped", "2D-S", "multi"),
        (ALL_FAMILIES, "2D-S", "ideal"), (ALL_FAMILIES, "2D-S", "multi"),
        (ALL_FAMILIES, "neural3d", "train"),
    ]
    sky = groups[0]
    assert (sky.buildings, sky.failed, sky.reasons) == (3, 1, ("c: no views",))
    assert (sky.wwr_ape.mean, sky.wwr_ape.std, sky.wwr_ape.count) == (15.0, 5.0, 2)
    assert sky.footprint_iou.count == 0
    pooled = groups[4]
    assert (pooled.buildings, pooled.failed, pooled.wwr_ape.mean) == (4, 1, 10.0)
    assert groups[1].footprint_iou == Summary(0.5, 0.0, 1)
    assert len(aggregate_by_family(rows, pooled=False)) == 4


def test_aggregate_of_nothing_is_empty():
    assert aggregate_by_family([]) == ()
