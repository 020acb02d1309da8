"""Footprint polygons: shapely in memory, GeoJSON on disk (world x/y metres)."""

from __future__ import annotations

from typing import Any

import shapely
from shapely.geometry import MultiPolygon, Polygon, mapping, shape

ROUND_DECIMALS = 9  # nm: enough for exact truth, short enough for byte-stable JSON


def polygon_to_geojson(polygon: Polygon | MultiPolygon) -> dict[str, Any]:
    """GeoJSON dict (``Polygon`` or ``MultiPolygon``) of a shapely polygon, x/y in metres.

    Exterior rings are written counter-clockwise and holes clockwise (RFC 7946);
    coordinates are rounded to nanometres so equal input gives equal bytes.
    """
    if polygon.is_empty:
        raise ValueError("cannot write an empty footprint")
    return _round(mapping(shapely.orient_polygons(polygon)))


def geojson_to_polygon(geojson: dict[str, Any]) -> Polygon | MultiPolygon:
    """Shapely polygon of a GeoJSON ``Polygon``/``MultiPolygon`` (or a Feature holding one).

    Raises
    ------
    ValueError
        If the GeoJSON is not a (multi)polygon or is invalid.
    """
    if geojson.get("type") == "Feature":
        geojson = geojson.get("geometry") or {}
    if geojson.get("type") not in ("Polygon", "MultiPolygon"):
        raise ValueError(f"footprint must be a GeoJSON Polygon, got type {geojson.get('type')!r}")
    try:
        geom = shape(geojson)
    except Exception as exc:  # shapely raises several types on malformed rings
        raise ValueError(f"malformed GeoJSON footprint: {exc}") from exc
    if not geom.is_valid:
        geom = geom.buffer(0)
    return geom


def _round(obj: Any) -> Any:
    if isinstance(obj, dict):
        return {k: _round(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_round(v) for v in obj]
    if isinstance(obj, float):
        return round(obj, ROUND_DECIMALS) + 0.0
    return obj
