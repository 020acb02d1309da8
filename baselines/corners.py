"""The four corners of the quadrilateral that best encloses a facade mask (2D-SS).

Algorithm (all in continuous image coordinates, pixel centres at +0.5):

1. Outer contours of the mask (OpenCV, every boundary pixel, all pieces) and
   their convex hull.
2. Minimum-area enclosing quadrilateral, greedily: while the hull has more than
   four edges, remove the edge whose removal (extending its two neighbours to
   their intersection) adds the least area. The result encloses the hull.
3. Sub-pixel refinement of each side: a total-least-squares line through the
   contour pixels that lie along the middle 80 % of the side, moved outward by
   half a pixel step along its normal (``max(|n_x|, |n_y|) / 2``: boundary pixel
   centres lie on average that far inside a straight edge), then neighbouring
   lines are intersected. A side with too few contour pixels (an occluded or
   cut edge, a gable) keeps its hull line.
4. Corners are ordered top-left, top-right, bottom-right, bottom-left.
"""

from __future__ import annotations

import cv2
import numpy as np

from baselines.views import ViewError
from envelope.polygons import polygon_area

_SIDE_BAND_PX = 2.0  # contour pixels within this distance inside a side belong to it
_SIDE_MIDDLE = (0.1, 0.9)  # part of a side used for the refit (corners are rounded)
_MIN_SIDE_POINTS = 8


def enclosing_quadrilateral(mask: np.ndarray) -> np.ndarray:
    """(4, 2) float64 corners (u, v) of the quadrilateral enclosing a (H, W) bool mask.

    Order: top-left, top-right, bottom-right, bottom-left.

    Raises
    ------
    ViewError
        If the mask is empty or too small to have four corners.
    """
    contour = outer_contour_uv(mask)
    hull = cv2.convexHull(contour.astype(np.float32)).reshape(-1, 2).astype(np.float64)
    if len(hull) < 4 or polygon_area(hull) < 4.0:
        raise ViewError("the facade mask is too small to have four corners")
    quad = minimum_area_quadrilateral(hull)
    quad = _refine_sides(quad, contour)
    return order_corners(quad)


def outer_contour_uv(mask: np.ndarray) -> np.ndarray:
    """(N, 2) float64 centres (u, v) of the boundary pixels of the mask's outer contours.

    All pieces count: a facade cut into strips by occluders is still one facade.

    Raises
    ------
    ViewError
        If the mask is empty.
    """
    mask = np.asarray(mask)
    if mask.ndim != 2:
        raise ValueError(f"mask must be (H, W), got shape {mask.shape}")
    contours, _ = cv2.findContours(
        mask.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE
    )
    if not contours:
        raise ViewError("the facade mask is empty")
    return np.concatenate([c.reshape(-1, 2) for c in contours]).astype(np.float64) + 0.5


def minimum_area_quadrilateral(hull: np.ndarray) -> np.ndarray:
    """(4, 2) quadrilateral enclosing a convex polygon ``hull`` (N, 2), N >= 4, greedily.

    Each step removes the edge whose two neighbours, extended to meet, add the
    least area. Exact for a polygon that is a quadrilateral with cut corners.
    """
    poly = [np.asarray(p, dtype=np.float64) for p in np.asarray(hull, dtype=np.float64)]
    if len(poly) < 4:
        raise ValueError(f"need a convex polygon with at least 4 vertices, got {len(poly)}")
    while len(poly) > 4:
        p = np.array(poly)
        n = len(p)
        prev, a, b, nxt = p[np.arange(n) - 1], p, np.roll(p, -1, 0), np.roll(p, -2, 0)
        d1, d2 = a - prev, b - nxt  # edge i-1 extended beyond a, edge i+1 beyond b
        denom = _cross(d1, -d2)
        with np.errstate(divide="ignore", invalid="ignore"):
            s = _cross(b - a, -d2) / denom
            r = _cross(d1, b - a) / denom
            valid = (np.abs(denom) > 1e-12) & (s >= 0) & (r >= 0)
            x = a + np.where(valid, s, 0.0)[:, None] * d1
        added = 0.5 * np.abs(_cross(x - a, b - a))
        added[~valid] = np.inf
        i = int(np.argmin(added))
        if not np.isfinite(added[i]):
            raise ValueError("hull is not convex; cannot reduce it to a quadrilateral")
        poly[i] = x[i]
        del poly[(i + 1) % n]
    return np.array(poly)


def order_corners(quad: np.ndarray) -> np.ndarray:
    """(4, 2) corners reordered top-left, top-right, bottom-right, bottom-left (image v down)."""
    q = np.asarray(quad, dtype=np.float64)
    if q.shape != (4, 2):
        raise ValueError(f"a quadrilateral is (4, 2), got {q.shape}")
    centre = q.mean(axis=0)
    angle = np.arctan2(q[:, 1] - centre[1], q[:, 0] - centre[0])
    q = q[np.argsort(angle)]  # clockwise on screen (v down), starting near the left
    start = int(np.argmin(q.sum(axis=1)))
    return np.roll(q, -start, axis=0)


def corners_inside_image(corners: np.ndarray, width: int, height: int, margin_px: float,
                         on_ground: np.ndarray | None = None) -> None:
    """Raise ViewError unless every corner lies at least ``margin_px`` inside the image.

    A corner on or beyond the border means the facade is cut off by the frame,
    so its size cannot be measured from this view, with one exception: a corner
    marked ``on_ground`` ((4,) bool, from depth and pose) that is only beyond the
    bottom border is the facade's foot, and a facade does not continue below the
    ground; a tightly framed photo puts the foot on the border.
    """
    c = np.asarray(corners, dtype=np.float64)
    inside_u = (c[:, 0] >= margin_px) & (c[:, 0] <= width - margin_px)
    inside_v = (c[:, 1] >= margin_px) & (c[:, 1] <= height - margin_px)
    bad = ~(inside_u & inside_v)
    if on_ground is not None:
        foot = np.asarray(on_ground, dtype=bool) & inside_u & (c[:, 1] > height - margin_px)
        bad &= ~foot
    if bad.any():
        where = ", ".join(f"({_fmt(u)}, {_fmt(v)})" for u, v in c[bad])
        raise ViewError(
            f"facade corner(s) {where} outside or on the border of the "
            f"{width}x{height} image (the facade is cut off)"
        )


def _fmt(x: float) -> str:
    return f"{round(float(x), 1) + 0.0:.1f}"  # + 0.0: no "-0.0"


def _refine_sides(quad: np.ndarray, contour: np.ndarray) -> np.ndarray:
    centre = quad.mean(axis=0)
    lines = []  # (normal, offset) with normal . x = offset, normal pointing outward
    for k in range(4):
        a, b = quad[k], quad[(k + 1) % 4]
        lines.append(_refit_side(a, b, centre, contour))
    out = np.empty((4, 2))
    for k in range(4):
        x = _intersect_lines(lines[k - 1], lines[k])
        out[k] = quad[k] if x is None else x
    return out


def _refit_side(a, b, centre, contour):
    t_dir = b - a
    length = np.linalg.norm(t_dir)
    n = np.array([t_dir[1], -t_dir[0]]) / length
    if n @ (a - centre) < 0:
        n = -n
    hull_line = (n, float(n @ a))
    dist = contour @ n - hull_line[1]
    t = (contour - a) @ t_dir / length**2
    sel = (dist >= -_SIDE_BAND_PX) & (dist <= 0.5) & (t >= _SIDE_MIDDLE[0]) & (t <= _SIDE_MIDDLE[1])
    pts = contour[sel]
    if len(pts) < max(_MIN_SIDE_POINTS, 0.2 * length):
        return hull_line
    mean = pts.mean(axis=0)
    _, _, vt = np.linalg.svd(pts - mean, full_matrices=False)
    m = vt[1]
    if m @ n < 0:
        m = -m
    half_step = 0.5 * max(abs(m[0]), abs(m[1]))
    return m, float(m @ mean) + half_step


def _intersect_lines(l1, l2):
    (n1, c1), (n2, c2) = l1, l2
    a = np.array([n1, n2])
    if abs(np.linalg.det(a)) < 1e-9:
        return None
    return np.linalg.solve(a, np.array([c1, c2]))


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
