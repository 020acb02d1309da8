"""Facade area split by class probabilities (neural3d.extraction.facade_split)."""

import numpy as np
import pytest
from scipy.special import erf
from sdf_shapes import box_sdf

from envelope.classes import NUM_CLASSES, SemanticClass
from neural3d.extraction.facade_groups import class_area_m2
from neural3d.extraction.facade_split import split_facade_area_by_probability
from neural3d.extraction.measure import measure_semantic_mesh
from neural3d.extraction.measure_config import MeasureConfig, MeasureStages
from neural3d.extraction.meshing import extract_mesh

WALL, WINDOW, ROOF = int(SemanticClass.WALL), int(SemanticClass.WINDOW), int(SemanticClass.ROOF)


def _probabilities(window: np.ndarray, roof: np.ndarray | None = None) -> np.ndarray:
    """(V, NUM_CLASSES): p(window) as given, the rest wall (or roof where ``roof``)."""
    p = np.zeros((len(window), NUM_CLASSES))
    p[:, WINDOW] = window
    p[:, WALL] = 1.0 - window
    if roof is not None:
        p[roof] = 0.0
        p[roof, ROOF] = 1.0
    return p


def test_quad_split_by_mean_probability():
    # a 2 x 1 m quad, all corners labelled wall; p(window) 0.25 at every corner
    v = np.array([[0, 0, 0], [2, 0, 0], [2, 0, 1], [0, 0, 1.0]])
    f = np.array([[0, 1, 2], [0, 2, 3]])
    shares = class_area_m2(v, f, np.full(4, WALL))
    out = split_facade_area_by_probability(shares, f, _probabilities(np.full(4, 0.25)))
    np.testing.assert_allclose(out[:, WINDOW].sum(), 0.5)
    np.testing.assert_allclose(out[:, WALL].sum(), 1.5)
    np.testing.assert_allclose(out.sum(axis=1), shares.sum(axis=1))  # nothing made or lost


def test_non_facade_part_and_one_hot_round_trip():
    v = np.array([[0, 0, 0], [2, 0, 0], [0, 3, 0], [0, 0, 1.0]])
    f = np.array([[0, 1, 2], [0, 1, 3]])
    labels = np.array([WINDOW, WINDOW, WALL, ROOF])
    shares = class_area_m2(v, f, labels)
    one_hot = np.eye(NUM_CLASSES)[labels]
    # one-hot probabilities of the labels give the labels' split back
    np.testing.assert_allclose(split_facade_area_by_probability(shares, f, one_hot), shares)
    # the roof share of triangle 1 stays; its facade 2/3 is split by the corners it has
    p = _probabilities(np.array([0.5, 0.5, 0.5, 0.0]), roof=np.array([False] * 3 + [True]))
    out = split_facade_area_by_probability(shares, f, p)
    np.testing.assert_allclose(out[0, [WINDOW, WALL]], [1.5, 1.5])
    np.testing.assert_allclose(out[1], shares[1])  # a roof-only corner: the labels' split


def _blurred_interval(x: np.ndarray, lo: float, hi: float, sigma: float) -> np.ndarray:
    """The indicator of [lo, hi] convolved with a Gaussian of ``sigma``: integrates to hi - lo."""
    s = sigma * np.sqrt(2.0)
    return 0.5 * (erf((x - lo) / s) - erf((x - hi) / s))


def test_blurred_window_keeps_its_area_where_the_argmax_loses_its_corners():
    # 6 x 4 x 10 m box; on every facade one 1.2 x 1.5 m window, its class blurred by
    # sigma = 0.2 m (a trained head at its grid cell): the argmax is a rounded rectangle
    sigma, half_w, z0, z1 = 0.2, 0.6, 4.0, 5.5

    def sdf(p):
        return box_sdf(p, [-3, -2, 0], [3, 2, 10])

    v, f = extract_mesh(sdf, [-4, -3, -1], [4, 3, 11], voxel_size_m=0.1)
    along = np.where(np.abs(np.abs(v[:, 0]) - 3) < 1e-6, v[:, 1], v[:, 0])  # (V,)
    p_window = (_blurred_interval(along, -half_w, half_w, sigma)
                * _blurred_interval(v[:, 2], z0, z1, sigma))
    roof = v[:, 2] > 10 - 1e-6
    p = _probabilities(p_window, roof=roof | (v[:, 2] < 1e-6))
    labels = np.argmax(p, axis=1)
    truth = 4 * 2 * half_w * (z1 - z0)  # 7.2 m²
    config = MeasureConfig(stages=MeasureStages().without("visibility_cull", "plane_probe"))
    hard = measure_semantic_mesh(v, f, labels, config=config)
    soft = measure_semantic_mesh(v, f, labels, config=config, vertex_probabilities=p)
    assert hard.window_area_m2 < 0.97 * truth  # the rounded corners
    # the blurred indicator integrates to the window's area; piecewise-linear on 0.1 m
    # triangles, within 1 %
    assert soft.window_area_m2 == pytest.approx(truth, rel=0.01)
    assert soft.facade_area_m2 == pytest.approx(hard.facade_area_m2)  # only the split moves


@pytest.mark.parametrize("probabilities, message", [
    (np.zeros((3, NUM_CLASSES)), "shape"),
    (np.full((4, NUM_CLASSES), -0.1), ">= 0"),
    (np.full((4, 2), 0.5), "shape"),
])
def test_bad_probabilities(probabilities, message):
    v = np.array([[0, 0, 0], [2, 0, 0], [2, 0, 1], [0, 0, 1.0]])
    f = np.array([[0, 1, 2], [0, 2, 3]])
    shares = class_area_m2(v, f, np.full(4, WALL))
    with pytest.raises(ValueError, match=message):
        split_facade_area_by_probability(shares, f, probabilities)
