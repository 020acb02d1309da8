"""Building footprint: the zero contour of an SDF near the ground, as a shapely polygon.

Two outlines. The **footprint** (:func:`footprint_from_sdf`) is the ground floor's: the
SDF is sampled on a square grid of ``cell_m`` over the box's x/y extent on
one or more horizontal planes ``z = heights_m`` and averaged over them
(defaults in :class:`neural3d.extract.ExtractConfig`: 1 to 2.5 m, above the
ground plane's reconstruction noise and below the lowest first floor, so that
upper floors, bays and balconies that reach beyond the ground floor stay out).
The **widest outline** (:func:`widest_outline_from_sdf`) is the union of the
sections from the lowest of those planes to the box top: what a roof plan draws. Across
a vertical wall the SDF does not change with z, so the average keeps the wall
where it is while the independent wobbles of a trained field on each plane
cancel. The grid is padded with one ring of positive (outside) samples so
that every contour closes, even where the building meets the box edge; the
zero contours (``skimage.measure.find_contours``, linear interpolation) become
rings, and nesting is resolved by even-odd (symmetric difference), which keeps
courtyards as holes. Pieces and holes smaller than ``min_area_m2`` are dropped.

The roofed-hole fill (``roofed_hole_fill``): a hole is a courtyard only if it is
open to the sky. Nothing constrains a trained field inside a building (no camera
sees it), so it may leave empty pockets there, which the planes cut as holes
(one L-shape lost 21 of its 121 m² to five of them). Each hole is probed along
vertical lines from the highest plane to the box top, at up to
:data:`HOLE_PROBE_LINES` points of a ``cell_m`` grid at least a cell inside it,
one sample per ``cell_m``: a line meets a surface where some sample is within
half a cell of it (|SDF| <= cell_m / 2, or inside). A hole where most lines
meet a surface is roofed over and is filled. This assumes no building has a
roofed hole in its footprint at 1-2.5 m: a covered passage or a glass-roofed
courtyard would be filled (footprint biased high).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from shapely.geometry import MultiPolygon, Polygon
from shapely.ops import unary_union

from neural3d.extraction.meshing import SdfFn, check_box, evaluate_points

MAX_FOOTPRINT_CELLS = 4096  # per axis: 16.8 M samples
HOLE_PROBE_LINES = 64  # vertical lines per footprint hole (open to the sky or roofed over)


def sample_sdf_plane(sdf_fn: SdfFn, xs: np.ndarray, ys: np.ndarray, height_m: float
                     ) -> np.ndarray:
    """SDF on the grid ``xs × ys`` at ``z = height_m``.

    Returns
    -------
    (nx, ny) float64 signed distances in m, indexed [ix, iy].
    """
    xx, yy = np.meshgrid(xs, ys, indexing="ij")
    pts = np.stack([xx.ravel(), yy.ravel(), np.full(xx.size, float(height_m))], axis=1)
    values = evaluate_points(sdf_fn, pts)
    if not np.isfinite(values).all():
        raise ValueError("the SDF returned NaN or inf on the footprint plane; check the field")
    return values.reshape(xx.shape).astype(np.float64)


def footprint_from_sdf(
    sdf_fn: SdfFn,
    box_min_m: np.ndarray,
    box_max_m: np.ndarray,
    *,
    heights_m: Sequence[float],
    cell_m: float,
    min_area_m2: float,
    roofed_hole_fill: bool = True,
) -> Polygon | MultiPolygon:
    """Footprint polygon (world x/y metres) where the SDF averaged over planes is negative.

    Parameters
    ----------
    sdf_fn : callable (N, 3) -> (N,)
        Signed distance in m, positive outside.
    box_min_m, box_max_m : (3,) float
        Scene box; its x/y extent is sampled and ``heights_m`` must lie in its z range.
    heights_m : sequence of float
        Heights of the planes in m above the world origin (ground at z = 0) over
        which the SDF is averaged; one value cuts a single plane.
    cell_m : float
        Grid spacing in m.
    min_area_m2 : float
        Pieces and holes smaller than this are dropped (slivers, noise).
    roofed_hole_fill : bool
        Fill the holes a surface roofs over (:func:`fill_roofed_holes`).

    Returns
    -------
    ``Polygon``, or ``MultiPolygon`` when several pieces are kept.

    Raises
    ------
    ValueError
        If the plane misses the building (no negative sample), lies wholly inside
        it, nothing is left after dropping small pieces, or on bad arguments.
    """
    lo, hi = check_box(box_min_m, box_max_m)
    heights = [float(h) for h in heights_m]
    if not heights:
        raise ValueError("heights_m is empty: give at least one footprint height")
    for height_m in heights:
        if not lo[2] <= height_m <= hi[2]:
            raise ValueError(f"footprint height {height_m} m lies outside the box's z range "
                             f"[{lo[2]:.3g}, {hi[2]:.3g}] m")
    if min_area_m2 < 0:
        raise ValueError(f"min_area_m2 must be >= 0, got {min_area_m2}")
    xs, ys = _grid_axes(lo, hi, cell_m)
    values = np.mean([sample_sdf_plane(sdf_fn, xs, ys, h) for h in heights], axis=0)
    where = f"z = {heights[0]} m" if len(heights) == 1 else f"z = {heights} m"
    if values.min() >= 0:
        raise ValueError(f"the plane(s) {where} miss the building (the SDF is positive "
                         "everywhere on them); choose footprint heights within the building")
    if values.max() <= 0:
        raise ValueError(f"the plane(s) {where} lie wholly inside the surface; the box is "
                         "too small or the field is degenerate")
    polygon = _polygon_from_grid(values, xs[0], ys[0], cell_m, min_area_m2)
    if not roofed_hole_fill:
        return polygon
    return fill_roofed_holes(polygon, sdf_fn, z_from_m=max(heights), z_to_m=float(hi[2]),
                             cell_m=cell_m)


def widest_outline_from_sdf(
    sdf_fn: SdfFn,
    box_min_m: np.ndarray,
    box_max_m: np.ndarray,
    *,
    from_height_m: float,
    step_m: float,
    cell_m: float,
    min_area_m2: float,
) -> Polygon | MultiPolygon:
    """The widest outline (world x/y metres): where the SDF is negative on any plane from
    ``from_height_m`` to the box top, ``step_m`` apart (the minimum of the planes' SDFs).

    The union of every storey's section: upper floors, bays and balconies beyond the ground
    floor are inside it. A part thinner than ``step_m`` (a balcony slab) may fall between
    two planes. Pieces and holes smaller than ``min_area_m2`` are dropped; holes are kept
    as they are (a courtyard open to the sky on every plane).

    Raises
    ------
    ValueError
        As :func:`footprint_from_sdf`, and if ``step_m`` is not > 0.
    """
    lo, hi = check_box(box_min_m, box_max_m)
    if not step_m > 0:
        raise ValueError(f"step_m must be > 0, got {step_m}")
    if not lo[2] <= from_height_m <= hi[2]:
        raise ValueError(f"from_height_m {from_height_m} m lies outside the box's z range "
                         f"[{lo[2]:.3g}, {hi[2]:.3g}] m")
    xs, ys = _grid_axes(lo, hi, cell_m)
    values = np.min([sample_sdf_plane(sdf_fn, xs, ys, h)
                     for h in np.arange(from_height_m, hi[2], step_m)], axis=0)
    if values.min() >= 0:
        raise ValueError("no plane meets the building (the SDF is positive everywhere on them)")
    return _polygon_from_grid(values, xs[0], ys[0], cell_m, min_area_m2)


def _grid_axes(lo: np.ndarray, hi: np.ndarray, cell_m: float) -> tuple[np.ndarray, np.ndarray]:
    """x and y sample positions (m) of a ``cell_m`` grid over the box's x/y extent."""
    if not np.isfinite(cell_m) or cell_m <= 0:
        raise ValueError(f"cell_m must be > 0, got {cell_m}")
    counts = np.floor((hi[:2] - lo[:2]) / cell_m + 1e-9).astype(int) + 1
    if counts.max() > MAX_FOOTPRINT_CELLS:
        raise ValueError(f"footprint grid of {tuple(counts)} cells is too large (at most "
                         f"{MAX_FOOTPRINT_CELLS} per axis); raise cell_m")
    xs, ys = (lo[i] + cell_m * np.arange(max(counts[i], 2)) for i in range(2))
    return xs, ys


def fill_roofed_holes(
    polygon: Polygon | MultiPolygon, sdf_fn: SdfFn, *, z_from_m: float, z_to_m: float,
    cell_m: float,
) -> Polygon | MultiPolygon:
    """``polygon`` (world x/y m) with every hole that a surface roofs over filled.

    A hole is probed along vertical lines from ``z_from_m`` to ``z_to_m`` at up to
    :data:`HOLE_PROBE_LINES` points of a ``cell_m`` grid at least ``cell_m`` inside
    it (its representative point if the grid has none), one SDF sample per ``cell_m``; a
    line meets a surface where a sample is inside or within ``cell_m / 2`` of one.
    Holes where more than half the lines meet a surface are filled; the others
    (courtyards open to the sky) stay. A piece that stood inside a filled hole merges
    with the piece around it, so the result is a valid (Multi)Polygon.
    """
    zs = np.arange(z_from_m, z_to_m + 1e-9, cell_m)
    if len(zs) == 0:
        return polygon
    pieces = []
    for piece in getattr(polygon, "geoms", [polygon]):
        holes = [ring for ring in piece.interiors
                 if not _roofed(Polygon(ring), sdf_fn, zs, cell_m)]
        pieces.append(Polygon(piece.exterior, holes))
    # a piece that stood in a filled hole (a pillar in a pocket) now lies inside its filler
    merged = unary_union(pieces)
    return merged if isinstance(merged, Polygon | MultiPolygon) else MultiPolygon(pieces)


def _roofed(hole: Polygon, sdf_fn: SdfFn, zs: np.ndarray, cell_m: float) -> bool:
    from shapely import contains_xy

    x0, y0, x1, y1 = hole.bounds
    gx, gy = np.meshgrid(np.arange(x0 + cell_m / 2, x1, cell_m),
                         np.arange(y0 + cell_m / 2, y1, cell_m), indexing="ij")
    core = hole.buffer(-cell_m)  # a line beside the hole's own wall would meet that wall
    inside = contains_xy(core, gx.ravel(), gy.ravel())
    xy = np.column_stack([gx.ravel()[inside], gy.ravel()[inside]])
    if len(xy) == 0:
        p = hole.representative_point()
        xy = np.array([[p.x, p.y]])
    xy = xy[np.linspace(0, len(xy) - 1, min(len(xy), HOLE_PROBE_LINES)).round().astype(int)]
    pts = np.concatenate([np.repeat(xy, len(zs), axis=0),
                          np.tile(zs, len(xy))[:, None]], axis=1)  # (L * Z, 3)
    sdf = evaluate_points(sdf_fn, pts).reshape(len(xy), len(zs))
    return bool(((sdf <= cell_m / 2).any(axis=1)).mean() > 0.5)


def _polygon_from_grid(
    values: np.ndarray, x0_m: float, y0_m: float, cell_m: float, min_area_m2: float
) -> Polygon | MultiPolygon:
    from skimage.measure import find_contours

    outside = max(float(values.max()), cell_m)
    padded = np.pad(values, 1, constant_values=outside)
    rings = []
    for contour in find_contours(padded, 0.0):
        xy = np.column_stack([x0_m + (contour[:, 0] - 1) * cell_m,
                              y0_m + (contour[:, 1] - 1) * cell_m])
        if len(xy) >= 4:
            ring = Polygon(xy).buffer(0)
            if not ring.is_empty:
                rings.append(ring)
    region = Polygon()
    for ring in rings:  # even-odd: a ring inside a piece is a hole, inside a hole an island
        region = region.symmetric_difference(ring)
    pieces = []
    for piece in getattr(region, "geoms", [region]):
        if isinstance(piece, Polygon) and piece.area >= max(min_area_m2, 1e-12):
            holes = [h for h in piece.interiors if Polygon(h).area >= min_area_m2]
            pieces.append(Polygon(piece.exterior, holes))
    if not pieces:
        raise ValueError(f"no footprint piece is at least {min_area_m2} m²; lower min_area_m2 "
                         "or check the footprint height")
    return pieces[0] if len(pieces) == 1 else MultiPolygon(pieces)
