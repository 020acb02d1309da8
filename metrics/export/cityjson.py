"""A building with one method's openings per facade as a CityJSON 2.0 LoD3 file.

The walls are the truth's (``BuildingTruth.facade_outlines_m``: one polygon per
wall, per facet of a curved wall), turned so that +y is true north (the
building's ``north_deg``), as in a projected map frame. Each wall is a
``WallSurface`` of a ``MultiSurface``; a facade with WWR ``w`` > 0 gets on each of
its walls one ``Window``: the wall polygon scaled by ``sqrt(w)`` about its
centroid (geomeppy's rule), so window / wall area is exactly ``w`` on every wall.
The window is a hole in its wall and a surface of its own filling it, linked by
the semantic ``parent`` / ``children``. Doors are not drawn (no method locates
them); each ``WallSurface`` carries the facade's figures as attributes: id,
azimuth, orientation, gross / window / door area, WWR (``null``: not estimated).

cjio turns the vertices into integers with a ``transform`` (mm precision) and
removes duplicates; the file has no ``referenceSystem`` (local metres).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from shapely.geometry import Polygon

from envelope.orientation import (
    CONVENTIONS,
    azimuth_deg_from_normal,
    orientation_bin,
    true_north_xy_from_world,
)
from envelope.polygons import newell_normal
from envelope.results import FacadeEstimate
from envelope.truth import BuildingTruth, FacadeTruth
from metrics.export.table import TRUTH_METHOD, North

CITYJSON_VERSION = "2.0"
LOD = "3"
IMPORTANT_DIGITS = 3  # vertices kept to 1 mm (cjio's compress)
MAX_DRAWN_WWR = 0.99  # a window as large as its wall would close the wall's ring onto itself


def cityjson_building(truth: BuildingTruth, north: North, method: str, protocol: str,
                      estimates: Sequence[FacadeEstimate] | None,
                      produced_by: str) -> dict[str, Any]:
    """The CityJSON document (a dict) of ``truth``'s walls with ``method``'s openings.

    ``estimates``: one per truth facade (the truth's ids, as
    :func:`metrics.score.facade_scoring.estimates_by_truth_facade` gives them); ``None``
    for the truth itself (method :data:`metrics.export.table.TRUTH_METHOD`).

    Raises
    ------
    ValueError
        If the truth has no facade outlines (imported meshes): there are no walls to draw.
    """
    CityJSON = _cjio_cityjson_class()
    if not truth.facade_outlines_m:
        raise ValueError(f"{truth.id} has no facade outlines in building.json (an imported "
                         "mesh): no walls to draw in CityJSON")
    by_id = {e.id: e for e in estimates} if estimates is not None else {}
    vertices: list[list[float]] = []
    boundaries: list[list[list[int]]] = []
    surfaces: list[dict[str, Any]] = []
    for facade in truth.facades:
        figures = _figures(facade, by_id.get(facade.id), estimates is None, north)
        for outline in truth.facade_outlines_m.get(facade.id, ()):
            corners = _true_north_corners(np.asarray(outline, dtype=np.float64), north.deg)
            window = _window_ring(corners, figures["wwr"])
            wall_rings = [corners] + ([window[::-1]] if window is not None else [])
            wall_index = len(surfaces)
            surfaces.append({"type": "WallSurface", **figures})
            boundaries.append([_add(vertices, ring) for ring in wall_rings])
            if window is not None:
                surfaces[wall_index]["children"] = [len(surfaces)]
                surfaces.append({"type": "Window", "parent": wall_index})
                boundaries.append([_add(vertices, window)])
    label = TRUTH_METHOD if estimates is None else f"{method} ({protocol})"
    document = {
        "type": "CityJSON", "version": CITYJSON_VERSION,
        "metadata": {"title": f"{truth.id}: walls of the truth, openings of {label}"},
        "CityObjects": {truth.id: {
            "type": "Building",
            "attributes": {"method": method, "protocol": protocol,
                           "north_deg": north.deg, "north_source": north.source,
                           "produced_by": produced_by, "conventions": list(CONVENTIONS)},
            "geometry": [{"type": "MultiSurface", "lod": LOD, "boundaries": boundaries,
                          "semantics": {"surfaces": surfaces,
                                        "values": list(range(len(boundaries)))}}],
        }},
        "vertices": vertices,
    }
    model = CityJSON(j=document)
    model.compress(important_digits=IMPORTANT_DIGITS)  # adds "transform", merges duplicates
    model.update_bbox()
    return model.j


def _cjio_cityjson_class() -> type:
    """``cjio.cityjson.CityJSON``, imported without its side effect on :mod:`json`.

    Importing cjio replaces ``json.encoder``'s float encoder and C encoder for the whole
    process (floats written with 6 digits from then on), which would round every JSON this
    process writes afterwards (result files, ``transforms.json``); both are put back.
    """
    import json.encoder

    saved = dict(vars(json.encoder))
    try:
        from cjio.cityjson import CityJSON
    finally:
        for name in set(vars(json.encoder)) - set(saved):
            delattr(json.encoder, name)  # cjio's `float` shadowing the builtin
        vars(json.encoder).update(saved)
    return CityJSON


def _figures(facade: FacadeTruth, estimate: FacadeEstimate | None, is_truth: bool,
             north: North) -> dict[str, Any]:
    azimuth = azimuth_deg_from_normal(facade.normal, north.deg)
    common = {"facade_id": facade.id, "azimuth_deg": _round(azimuth),
              "orientation": None if azimuth is None else orientation_bin(azimuth)}
    if is_truth:
        return {**common, "gross_area_m2": _round(facade.facade_area_m2),
                "window_area_m2": _round(facade.window_area_m2),
                "door_area_m2": _round(facade.door_area_m2), "wwr": _round(facade.wwr)}
    if estimate is None or estimate.missing or estimate.wwr is None:
        return {**common, "gross_area_m2": None, "window_area_m2": None, "door_area_m2": None,
                "wwr": None}
    return {**common, "gross_area_m2": _round(estimate.facade_area_m2),
            "window_area_m2": _round(estimate.window_area_m2), "door_area_m2": None,
            "wwr": _round(estimate.wwr)}


def _true_north_corners(corners_world: np.ndarray, north_deg: float) -> np.ndarray:
    """(n, 3) wall corners with x/y turned so that +y is true north; z unchanged."""
    xy = true_north_xy_from_world(corners_world[:, :2], north_deg)
    return np.column_stack([xy, corners_world[:, 2]])


def _window_ring(corners: np.ndarray, wwr: float | None) -> np.ndarray | None:
    """(n, 3) ring: the wall scaled by sqrt(wwr) about its centroid, or None for no window.

    Raises ValueError if the scaled ring leaves a (non-convex) wall.
    """
    if wwr is None or wwr <= 0:
        return None
    origin, u, v = _plane_frame(corners)
    plan = Polygon(np.stack([(corners - origin) @ u, (corners - origin) @ v], axis=1))
    cx, cy = plan.centroid.x, plan.centroid.y
    scale = math.sqrt(min(wwr, MAX_DRAWN_WWR))
    ring2d = np.asarray(plan.exterior.coords)[:-1]
    ring2d = np.stack([cx + scale * (ring2d[:, 0] - cx), cy + scale * (ring2d[:, 1] - cy)],
                      axis=1)
    if not plan.contains(Polygon(ring2d)):
        raise ValueError("a window scaled about a wall's centroid would leave the (non-convex) "
                         "wall")
    return origin + ring2d[:, :1] * u + ring2d[:, 1:] * v  # the wall's own winding


def _plane_frame(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Origin and in-plane axes u, v (v x u along the outward normal of a CCW ring)."""
    origin = corners[0]
    u = corners[1] - corners[0]
    u /= np.linalg.norm(u)
    normal = newell_normal(corners)
    v = np.cross(normal, u)
    return origin, u, v


def _add(vertices: list[list[float]], ring: np.ndarray) -> list[int]:
    start = len(vertices)
    vertices.extend([float(c) for c in p] for p in ring)
    return list(range(start, start + len(ring)))


def _round(value: float | None) -> float | None:
    return None if value is None else round(float(value), 6) + 0.0
