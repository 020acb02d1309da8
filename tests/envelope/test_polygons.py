"""envelope.polygons: the shoelace area and Newell's normal on closed-form polygons, and
each written once in the sources (no second shoelace or Newell sum elsewhere)."""

from __future__ import annotations

import ast

import numpy as np
import pytest
from paths import REPO_ROOT

from envelope.polygons import newell_normal, newell_vector, polygon_area

PACKAGES = ("envelope", "dataset", "baselines", "neural3d", "segment", "metrics", "figures")


def _regular_polygon(n: int, radius: float) -> np.ndarray:
    angles = 2 * np.pi * np.arange(n) / n
    return radius * np.stack([np.cos(angles), np.sin(angles)], axis=1)


def test_area_of_closed_form_polygons():
    assert polygon_area(np.array([[0, 0], [4, 0], [4, 3], [0, 3]])) == 12.0  # rectangle
    assert polygon_area(np.array([[0, 0], [4, 0], [0, 3]])) == 6.0  # right triangle
    assert polygon_area(np.array([[0, 0], [4, 0], [3, 2], [1, 2]])) == 6.0  # trapezium
    # an L: 4 x 4 square less its 2 x 2 corner, clockwise (orientation does not matter)
    ell = np.array([[0, 0], [0, 4], [2, 4], [2, 2], [4, 2], [4, 0]], dtype=float)
    assert polygon_area(ell) == 12.0 and polygon_area(ell[::-1]) == 12.0
    # regular n-gon of circumradius r: n r² sin(2π/n) / 2, to rounding
    for n in (5, 12, 100):
        assert polygon_area(_regular_polygon(n, 3.0)) == pytest.approx(
            n * 9.0 * np.sin(2 * np.pi / n) / 2, rel=1e-12)
    with pytest.raises(ValueError, match=r"\(n, 2\)"):
        polygon_area(np.zeros((4, 3)))


def test_newell_normal_of_closed_form_rings():
    # the 2 x 3 rectangle in z = 5, counter-clockwise seen from +z: area 6, normal +z
    ring = np.array([[0, 0, 5], [2, 0, 5], [2, 3, 5], [0, 3, 5]], dtype=float)
    assert np.array_equal(newell_vector(ring), [0.0, 0.0, 12.0])  # twice the area
    assert np.array_equal(newell_normal(ring[::-1]), [0.0, 0.0, -1.0])
    # a wall in the plane x + y = 1 (a vertical 45° facade), seen from (1, 1, 0) outside
    wall = np.array([[1, 0, 0], [0, 1, 0], [0, 1, 2], [1, 0, 2]], dtype=float)
    np.testing.assert_allclose(newell_normal(wall), [2 ** -0.5, 2 ** -0.5, 0.0], atol=1e-15)
    # a rotated, shifted regular 12-gon: the normal is the rotation's z axis and |vector|/2
    # its area
    rotation = np.array([[1, 0, 0], [0, 0.6, -0.8], [0, 0.8, 0.6]])
    flat = np.column_stack([_regular_polygon(12, 2.0), np.zeros(12)])
    moved = flat @ rotation.T + [10.0, -3.0, 7.0]
    np.testing.assert_allclose(newell_normal(moved), rotation[:, 2], atol=1e-12)
    assert np.linalg.norm(newell_vector(moved)) / 2 == pytest.approx(
        polygon_area(flat[:, :2]), rel=1e-12)
    with pytest.raises(ValueError, match="one line"):
        newell_normal(np.array([[0, 0, 0], [1, 1, 1], [2, 2, 2]], dtype=float))


def _shoelace_or_newell(node: ast.AST) -> bool:
    """``0.5 * abs(...np.roll...)`` (a shoelace), a sum of a ring's cross products with the
    next corner's (``np.roll`` in a sum or a loop of ``cross``) or Newell's products
    (``sum((p[:, 1] - q[:, 1]) * (p[:, 2] + q[:, 2]))``)."""
    text = ast.unparse(node)
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Mult):
        return "0.5" in ast.unparse(node.left) and "abs(" in text and "roll(" in text
    if isinstance(node, ast.Call) and "sum" in ast.unparse(node.func):
        return ("roll(" in text and "cross" in text) or ("[:, 1] -" in text
                                                          and "[:, 2] +" in text)
    if isinstance(node, ast.For):
        return "roll(" in ast.unparse(node.iter) and any(
            "cross(" in ast.unparse(b) for b in node.body)
    return False


@pytest.mark.slow
def test_each_formula_is_written_once():
    found = []
    for package in PACKAGES:
        for path in sorted((REPO_ROOT / package).rglob("*.py")):
            for node in ast.walk(ast.parse(path.read_text())):
                if _shoelace_or_newell(node):
                    found.append(f"{path.relative_to(REPO_ROOT)}:{node.lineno}")
    assert found and all(f.startswith("envelope/polygons.py:") for f in found), found
