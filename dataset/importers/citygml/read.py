"""Read the buildings of a CityGML 2.0 or 3.0 file: semantic polygons, CRS, attributes (lxml).

Each ``Building`` and each ``BuildingPart`` becomes one :class:`CityBuilding` holding the
polygons that its semantic elements own (a part's polygons are its own, not its parent's).
A polygon's kind is that of its nearest semantic ancestor (:data:`SURFACE_KINDS`): the
boundary surfaces (``WallSurface``, ``RoofSurface``, ``GroundSurface``, ...), the openings
(2.0: ``bldg:Window``/``bldg:Door`` under ``bldg:opening``; 3.0: ``con:Window``/``con:Door``
fillings and their ``con:WindowSurface``/``con:DoorSurface``) and installations. Elements are
matched by local name, so the 2.0 and 3.0 namespaces read alike. Geometry without
semantics (a building's own ``lod3Solid``) is left out: in these files it repeats the
boundary surfaces. ``surfaceMember xlink:href="#id"`` is followed; a polygon counts once per
building. ``OrientableSurface orientation="-"`` reverses its rings.

Errors name the file and the element's ``gml:id`` (:class:`CityGmlError`).
"""

from __future__ import annotations

import lzma
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import numpy as np

from dataset.importers.citygml.appearance import PolygonLook, polygon_looks
from dataset.importers.citygml.files import (
    CITYGML_NAMESPACES,
    CityGmlError,
    open_citygml,
)

SurfaceKind = Literal["wall", "roof", "ground", "closure", "outer_floor", "outer_ceiling",
                      "window", "door", "installation", "interior"]
SURFACE_KINDS: dict[str, SurfaceKind] = {
    "WallSurface": "wall",
    "RoofSurface": "roof",
    "GroundSurface": "ground",
    "ClosureSurface": "closure",
    "OuterFloorSurface": "outer_floor",
    "OuterCeilingSurface": "outer_ceiling",
    "Window": "window",
    "WindowSurface": "window",
    "Door": "door",
    "DoorSurface": "door",
    "BuildingInstallation": "installation",
    "BuildingConstructiveElement": "installation",
    "InteriorWallSurface": "interior",
    "FloorSurface": "interior",
    "CeilingSurface": "interior",
    "IntBuildingInstallation": "interior",
    "BuildingFurniture": "interior",
    "BuildingRoom": "interior",
}
"""Local element name -> what its polygons are (2.0 and 3.0 names)."""
OPENING_KINDS: tuple[SurfaceKind, ...] = ("window", "door")
BUILDING_TAGS = ("Building", "BuildingPart")
CITYGML_VERSIONS = dict(zip(CITYGML_NAMESPACES, ("2.0", "3.0")))
GEOGRAPHIC_EPSG = frozenset({4326, 4258, 4269, 4937, 4979, 4978, 4289, 4167})
"""EPSG codes in degrees (or geocentric): refused, the importer needs metres."""
_ADV_CRS = {"ETRS89_UTM32": 25832, "ETRS89_UTM33": 25833}  # German AdV names (urn:adv:crs:...)
_XLINK_HREF = "{http://www.w3.org/1999/xlink}href"
_EPSG_PATTERNS = (re.compile(r"EPSG:{1,2}(\d+)", re.I), re.compile(r"/EPSG/\d+/(\d+)", re.I))


@dataclass(frozen=True)
class CityPolygon:
    """One ``gml:Polygon`` of a building, in the file's CRS (metres).

    ``rings_m``: exterior ring first, then the holes, each (n, 3) float64 without the
    repeated closing point. ``owner_id``: the ``gml:id`` of the element it belongs to (the
    window, door or installation for those; the boundary surface's id, or the building's
    id when the surface has none). ``polygon_id``: the polygon's own ``gml:id``
    (``"<owner_id>#<k>"`` when it has none). ``ring_ids``: each ring's ``gml:id`` (``""``
    when it has none), what texture coordinates name; ``reversed``: the rings are the file's
    in reverse order (an ``OrientableSurface orientation="-"``).
    """

    polygon_id: str
    kind: SurfaceKind
    owner_id: str
    rings_m: tuple[np.ndarray, ...]
    ring_ids: tuple[str, ...] = ()
    reversed: bool = False


@dataclass(frozen=True)
class CityBuilding:
    """A ``Building`` or ``BuildingPart``: its id, its polygons and its attributes.

    ``attributes``: generic string attributes (``dataAvailable``, ...) and the ``function``,
    ``class`` and ``usage`` codes where given. ``warnings``: one line per repaired element
    (a degenerate ring dropped), naming its ``gml:id``. ``parent_id``: the enclosing
    building's ``gml:id`` for a ``BuildingPart``. A building without any semantic surface
    (a part written as plain geometry) has its own polygons read as ``"installation"``.
    """

    gml_id: str
    is_part: bool
    polygons: tuple[CityPolygon, ...]
    attributes: dict[str, str] = field(default_factory=dict)
    warnings: tuple[str, ...] = ()
    parent_id: str | None = None


@dataclass(frozen=True)
class CityModel:
    """What :func:`read_citygml` found: version (``"2.0"``/``"3.0"``), CRS as ``EPSG:<code>``,
    the buildings in file order, and the polygons' looks (polygon ``gml:id`` ->
    :class:`dataset.importers.citygml.appearance.PolygonLook`)."""

    path: Path
    version: str
    crs: str
    buildings: tuple[CityBuilding, ...]
    looks: dict[str, PolygonLook] = field(default_factory=dict)


def read_citygml(path: str | Path) -> CityModel:
    """Read every ``Building``/``BuildingPart`` of a CityGML 2.0 or 3.0 file.

    Raises
    ------
    CityGmlError
        Missing file, XML that is not well formed (e.g. truncated), a root that is not a
        CityGML ``CityModel``, no building, a missing, unknown or geographic CRS, a ring with
        fewer than three points or a coordinate count not a multiple of three, an xlink to
        nothing. A ring of three or more points of which fewer than three are distinct has no
        area: it is dropped (a hole) or drops its polygon, and listed in the building's
        ``warnings``. Files compressed with gzip, xz or bzip2 (``.gz``, ``.xz``, ``.bz2``)
        are read as they are.
    """
    from lxml import etree

    path = Path(path)
    if not path.is_file():
        raise CityGmlError(f"CityGML file {path} does not exist")
    try:
        with open_citygml(path) as fh:
            tree = etree.parse(fh, etree.XMLParser(huge_tree=True, resolve_entities=False))
    except (etree.XMLSyntaxError, EOFError, OSError, lzma.LZMAError) as exc:
        raise CityGmlError(
            f"{path} is not well-formed XML ({exc}); a truncated download or copy ends like "
            "this: fetch the file again") from exc
    root = tree.getroot()
    version = CITYGML_VERSIONS.get(etree.QName(root).namespace or "")
    if etree.QName(root).localname != "CityModel" or version is None:
        raise CityGmlError(
            f"{path} is not CityGML 2.0 or 3.0: its root element is {root.tag!r}, expected "
            "CityModel in the namespace http://www.opengis.net/citygml/2.0 or /3.0")
    by_id = {i: el for el in root.iter() if isinstance(el.tag, str)
             for i in [_gml_id(el)] if i is not None}
    buildings = []
    for el in root.iter(*(f"{{*}}{t}" for t in BUILDING_TAGS)):
        gml_id = _gml_id(el) or f"{etree.QName(el).localname}#{len(buildings) + 1}"
        warnings: list[str] = []
        polygons = tuple(_building_polygons(path, el, gml_id, by_id, warnings))
        if not polygons:  # a part modelled as plain geometry: read it as an installation
            polygons = tuple(_building_polygons(path, el, gml_id, by_id, warnings,
                                                plain="installation"))
        parent = next((a for a in el.iterancestors() if _local(a) in BUILDING_TAGS), None)
        buildings.append(CityBuilding(
            gml_id=gml_id, is_part=etree.QName(el).localname == "BuildingPart",
            polygons=polygons, attributes=_attributes(el), warnings=tuple(warnings),
            parent_id=None if parent is None else _gml_id(parent)))
    if not buildings:
        raise CityGmlError(f"{path} holds no Building or BuildingPart element")
    return CityModel(path, version, _crs(path, root, buildings[0].gml_id), tuple(buildings),
                     polygon_looks(root))


def _gml_id(el) -> str | None:
    for key, value in el.attrib.items():
        if key.endswith("}id") and "gml" in key:
            return value
    return None


def _local(el) -> str:
    tag = el.tag
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else ""


def _semantic_owner(el, building, plain: SurfaceKind | None = None):
    """Nearest semantic ancestor of ``el`` below ``building``: (element, kind), or None when
    the walk meets another building part first or finds no semantics (with ``plain``: then
    ``(building, plain)``)."""
    node = el.getparent()
    while node is not None and node is not building:
        name = _local(node)
        if name in BUILDING_TAGS:
            return None
        if name in SURFACE_KINDS:
            return None if plain else (node, SURFACE_KINDS[name])
        node = node.getparent()
    return None if plain is None else (building, plain)


def _building_polygons(path: Path, building, building_id: str, by_id: dict,
                       warnings: list[str], plain: SurfaceKind | None = None):
    seen: set[str] = set()
    for anchor, polygon, reverse in _polygon_sources(path, building, building_id, by_id):
        owner = _semantic_owner(anchor, building, plain)
        if owner is None:
            continue
        owner_el, kind = owner
        owner_id = _gml_id(owner_el) or building_id
        polygon_id = _gml_id(polygon) or f"{owner_id}#{len(seen) + 1}"
        if polygon_id in seen:
            continue
        seen.add(polygon_id)
        ring_els = _rings(polygon)
        rings = [_ring_points(path, r, polygon_id) for r in ring_els]
        if not rings:
            raise CityGmlError(f"{path}: polygon {polygon_id} has no exterior ring")
        if rings[0] is None:
            warnings.append(f"polygon {polygon_id}: exterior ring of fewer than three distinct "
                            "points (no area), polygon dropped")
            continue
        if any(r is None for r in rings[1:]):
            warnings.append(f"polygon {polygon_id}: hole of fewer than three distinct points "
                            "(no area), hole dropped")
        ring_ids = tuple(_gml_id(e) or "" for e, r in zip(ring_els, rings) if r is not None)
        rings = tuple(r[::-1] if reverse else r for r in rings if r is not None)
        yield CityPolygon(polygon_id, kind, owner_id, rings, ring_ids, reverse)


def _polygon_sources(path: Path, building, building_id: str, by_id: dict):
    """(anchor, gml:Polygon, reversed) for every polygon under ``building``, inline or through
    an ``xlink:href`` (to a polygon or to a surface holding polygons); the anchor is where
    the polygon is used, which decides its semantics."""
    for polygon in building.iter("{*}Polygon"):
        yield polygon, polygon, _reversed(polygon)
    for anchor in building.iter("{*}surfaceMember", "{*}baseSurface"):
        ref = (anchor.get(_XLINK_HREF) or "").lstrip("#")
        if not ref:
            continue
        target = by_id.get(ref)
        if target is None:
            raise CityGmlError(f"{path}: building {building_id}: xlink:href '#{ref}' "
                               "points to no element with that gml:id in this file")
        holder = anchor.getparent()
        reverse = (_local(anchor) == "baseSurface" and holder is not None
                   and _local(holder) == "OrientableSurface"
                   and holder.get("orientation") == "-")
        if _local(target) == "Polygon":  # its own place's orientation is not this use's
            yield anchor, target, reverse
            continue
        for polygon in target.iter("{*}Polygon"):
            yield anchor, polygon, reverse != _reversed(polygon)


def _reversed(polygon) -> bool:
    """Whether ``polygon`` is the base surface of an ``OrientableSurface orientation="-"``."""
    holder = polygon.getparent()
    orientable = holder.getparent() if holder is not None else None
    return (orientable is not None and _local(orientable) == "OrientableSurface"
            and orientable.get("orientation") == "-")


def _rings(polygon) -> list:
    rings = []
    for part in ("exterior", "interior"):
        for holder in polygon.findall(f"{{*}}{part}"):
            ring = holder.find("{*}LinearRing")
            if ring is not None:
                rings.append(ring)
    return rings


def _ring_points(path: Path, ring, polygon_id: str) -> np.ndarray | None:
    """(n, 3) corners of ``ring`` without the closing repeat; None for a ring of fewer than
    three distinct points (a degenerate ring exporters leave behind)."""
    ring_id = _gml_id(ring) or polygon_id
    pos_list = ring.find("{*}posList")
    if pos_list is not None:
        dim = int(pos_list.get("srsDimension") or _inherited_dimension(ring))
        values = (pos_list.text or "").split()
    else:
        pos = ring.findall("{*}pos")
        coords = ring.find("{*}coordinates")
        if pos:
            rows = [(p.text or "").split() for p in pos]
            dim = len(rows[0])
            values = [v for row in rows for v in row]
        elif coords is not None:
            rows = [t.split(",") for t in (coords.text or "").split()]
            dim = len(rows[0]) if rows else 3
            values = [v for row in rows for v in row]
        else:
            raise CityGmlError(f"{path}: ring {ring_id} of polygon {polygon_id} has no "
                               "coordinates (posList, pos or coordinates)")
    if dim != 3 or len(values) % 3:
        raise CityGmlError(f"{path}: ring {ring_id} of polygon {polygon_id} has "
                           f"{len(values)} numbers in dimension {dim}; LoD3 needs x y z "
                           "triples")
    try:
        pts = np.asarray(values, dtype=np.float64).reshape(-1, 3)
    except ValueError as exc:
        raise CityGmlError(f"{path}: ring {ring_id} of polygon {polygon_id} holds a "
                           f"coordinate that is not a number ({exc})") from exc
    if not np.isfinite(pts).all():
        raise CityGmlError(f"{path}: ring {ring_id} of polygon {polygon_id} holds NaN or inf")
    if len(pts) > 1 and np.array_equal(pts[0], pts[-1]):
        pts = pts[:-1]
    if len(pts) < 3:
        raise CityGmlError(f"{path}: ring {ring_id} of polygon {polygon_id} has {len(pts)} "
                           "point(s); a ring needs at least three")
    if len(np.unique(pts, axis=0)) < 3:
        return None  # repeats one or two points: no area, dropped with a warning
    return pts


def _inherited_dimension(el) -> int:
    node = el
    while node is not None:
        dim = node.get("srsDimension")
        if dim:
            return int(dim)
        node = node.getparent()
    return 3


def _crs(path: Path, root, first_id: str) -> str:
    names = [el.get("srsName") for el in root.iter() if isinstance(el.tag, str)
             and el.get("srsName")]
    if not names:
        raise CityGmlError(
            f"{path}: no srsName anywhere (building {first_id}); the CRS must be known to "
            "map results back: add srsName=\"EPSG:<code>\" to the CityModel's gml:Envelope")
    codes = {_epsg_code(n) for n in names}
    if None in codes or len(codes) != 1:
        raise CityGmlError(
            f"{path}: building {first_id}: unknown or mixed CRS {sorted(set(names))}; give one "
            "projected CRS in metres as EPSG:<code> (e.g. EPSG:32632 or EPSG:25832)")
    code = codes.pop()
    if code in GEOGRAPHIC_EPSG:
        raise CityGmlError(
            f"{path}: building {first_id}: CRS EPSG:{code} is in degrees or geocentric; "
            "reproject the file to a projected CRS in metres (UTM, Gauss-Krueger) first")
    return f"EPSG:{code}"


def _epsg_code(name: str) -> int | None:
    for pattern in _EPSG_PATTERNS:
        m = pattern.search(name)
        if m:
            return int(m.group(1))
    for adv, code in _ADV_CRS.items():
        if f"urn:adv:crs:{adv}".lower() in name.lower():
            return code
    return None


def _attributes(building) -> dict[str, str]:
    """Generic string attributes and function/class/usage codes directly on ``building``."""
    out: dict[str, str] = {}
    for child in building:
        name = _local(child)
        if name == "stringAttribute" and child.get("name"):
            out[child.get("name")] = (child.findtext("{*}value") or "").strip()
        elif name == "genericAttribute":  # 3.0: gen:StringAttribute with gen:name/gen:value
            for attr in child:
                key = attr.findtext("{*}name")
                if key:
                    out[key.strip()] = (attr.findtext("{*}value") or "").strip()
        elif name in ("function", "class", "usage") and child.text:
            out[name] = child.text.strip()
    return out
