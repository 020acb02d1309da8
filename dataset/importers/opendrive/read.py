"""OpenDRIVE road networks (``.xodr``, also ``.gz``/``.xz``): roads' reference lines and their
lanes' centre lines, sampled to polylines in the file's frame.

**Reference line** (``planView``): a road's ``geometry`` records in order, each starting at
``(x, y)`` with heading ``hdg`` (radians, counter-clockwise from +x) and running ``length``
metres of arc: ``line``; ``arc`` (constant ``curvature``, 1/m, positive to the left);
``spiral`` (a clothoid: curvature linear in s from ``curvStart`` to ``curvEnd``, closed form
with Fresnel integrals, :func:`spiral_xy`); ``poly3`` (v = a + b u + c u^2 + d u^3 in the
record's local u/v frame, u found by arc length); ``paramPoly3`` (u(p), v(p) cubic in p,
``pRange`` ``arcLength``: p in [0, length], or ``normalized``: p in [0, 1], p taken
proportional to s). ``elevationProfile`` gives z(s) (cubic per record).

**Lanes.** ``laneOffset`` (cubic in s) shifts the centre lane (id 0) to the left of the
reference line; each ``laneSection`` lists lanes left (ids 1, 2, ... outwards) and right
(-1, -2, ...) with their ``width`` records (cubic in the distance from the section's start
plus ``sOffset``). A lane's centre lies ``laneOffset + (sum of the widths of the lanes
between it and the centre) + half its own width`` to the left (left lanes) or right (right
lanes) of the reference line, along the left normal ``(-sin hdg, cos hdg)``. Lanes given by
``border`` records instead of widths are not read (the Ingolstadt file has none).

**Frame.** Points are in the file's frame: the ``header``'s ``geoReference`` (a PROJ string)
after its ``offset`` (rotate by ``hdg`` about z, then add ``x``, ``y``, ``z``; absent: none).
Mapping that frame to a scene's world frame is :mod:`dataset.importers.opendrive.streets`.
"""

from __future__ import annotations

import gzip
import lzma
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
from lxml import etree
from scipy.special import fresnel

SAMPLE_STEP_M = 0.5
"""Largest arc length between two samples of a line: on the tightest bend of the Ingolstadt
file's reference lines (radius 2.0 m, road 1446000) a 0.5 m chord misses the curve by 16 mm,
and most of its bends are far wider; street cameras stand metres apart."""
_OPENERS = {".gz": gzip.open, ".xz": lzma.open}


class OpenDriveError(ValueError):
    """Bad OpenDRIVE input; the message names the file and the road."""


@dataclass(frozen=True)
class Geometry:
    """One ``planView/geometry`` record: start ``s_m``, ``x_m``, ``y_m``, ``hdg_rad``,
    ``length_m``, its ``kind`` (``line``, ``arc``, ``spiral``, ``poly3``, ``paramPoly3``)
    and that element's attributes as floats (``pRange`` as 1.0 for ``normalized``)."""

    s_m: float
    x_m: float
    y_m: float
    hdg_rad: float
    length_m: float
    kind: str
    params: tuple[tuple[str, float], ...] = ()

    def param(self, name: str) -> float:
        return dict(self.params).get(name, 0.0)


@dataclass(frozen=True)
class Cubic:
    """``a + b ds + c ds^2 + d ds^3`` from ``s_m`` on (ds = s - s_m)."""

    s_m: float
    a: float
    b: float
    c: float
    d: float


@dataclass(frozen=True)
class Lane:
    """A lane of a section: ``id`` (> 0 left, < 0 right), ``type`` (``driving``,
    ``sidewalk``, ...) and its width records (``s_m`` from the section's start)."""

    id: int
    type: str
    widths: tuple[Cubic, ...]


@dataclass(frozen=True)
class LaneSection:
    s_m: float
    lanes: tuple[Lane, ...]


@dataclass(frozen=True)
class Road:
    """A road: ``id``, ``junction`` (``-1`` outside junctions), ``length_m``, its reference
    line's records, elevation, lane offset and lane sections."""

    id: str
    junction: str
    length_m: float
    geometry: tuple[Geometry, ...]
    elevation: tuple[Cubic, ...]
    lane_offset: tuple[Cubic, ...]
    sections: tuple[LaneSection, ...]


@dataclass(frozen=True)
class RoadNetwork:
    """A file's roads; ``geo_reference``: the header's PROJ string ('' when absent);
    ``offset``: the header's ``(x, y, z, hdg)``."""

    path: Path
    geo_reference: str
    offset: tuple[float, float, float, float]
    roads: tuple[Road, ...]


@dataclass(frozen=True)
class LaneLine:
    """A lane's centre line over one lane section: ``points_m`` (N, 3) in the file's frame,
    in the road's s order, and ``heading_rad`` (N,) of the reference line there."""

    road_id: str
    lane_id: int
    type: str
    points_m: np.ndarray
    heading_rad: np.ndarray


@lru_cache(maxsize=4)
def read_opendrive(path: str | Path) -> RoadNetwork:
    """Parse an OpenDRIVE file (plain, ``.gz`` or ``.xz``); cached per path.

    Raises
    ------
    OpenDriveError
        Unreadable XML, a root that is not ``OpenDRIVE``, a road without ``planView``
        geometry or with an unknown geometry kind.
    """
    path = Path(path)
    try:
        with _OPENERS.get(path.suffix.lower(), open)(path, "rb") as fh:
            root = etree.parse(fh).getroot()
    except (OSError, EOFError, lzma.LZMAError, etree.XMLSyntaxError) as exc:
        raise OpenDriveError(f"{path}: not readable OpenDRIVE XML ({exc})") from exc
    if etree.QName(root).localname != "OpenDRIVE":
        raise OpenDriveError(f"{path}: root element is {root.tag!r}, not OpenDRIVE")
    header = root.find("header")
    geo = header.findtext("geoReference", "").strip() if header is not None else ""
    off = header.find("offset") if header is not None else None
    offset = tuple(_f(off, k) for k in ("x", "y", "z", "hdg")) if off is not None else (
        0.0, 0.0, 0.0, 0.0)
    return RoadNetwork(path, geo, offset, tuple(_road(path, r) for r in root.iter("road")))


def reference_points(road: Road, s_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(N, 2) x/y and (N,) heading of ``road``'s reference line at arc lengths ``s_m`` (N,)
    (file frame before the header's offset)."""
    s_m = np.asarray(s_m, dtype=np.float64)
    starts = np.array([g.s_m for g in road.geometry])
    which = np.clip(np.searchsorted(starts, s_m, side="right") - 1, 0, len(starts) - 1)
    xy, hdg = np.empty((len(s_m), 2)), np.empty(len(s_m))
    for k in np.unique(which):
        g = road.geometry[k]
        ds = np.clip(s_m[which == k] - g.s_m, 0.0, g.length_m)
        xy[which == k], hdg[which == k] = geometry_xy(g, ds)
    return xy, hdg


def geometry_xy(g: Geometry, ds_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(N, 2) x/y and (N,) heading ``ds_m`` (N,) metres of arc along one record."""
    ds = np.asarray(ds_m, dtype=np.float64)
    if g.kind == "line":
        return _placed(g, np.stack([ds, np.zeros_like(ds)], axis=1), np.zeros_like(ds))
    if g.kind == "arc":
        k = g.param("curvature")
        if k == 0.0:
            return geometry_xy(Geometry(g.s_m, g.x_m, g.y_m, g.hdg_rad, g.length_m, "line"), ds)
        local = np.stack([np.sin(k * ds) / k, (1.0 - np.cos(k * ds)) / k], axis=1)
        return _placed(g, local, k * ds)
    if g.kind == "spiral":
        k0, k1 = g.param("curvStart"), g.param("curvEnd")
        local, turn = spiral_xy(k0, (k1 - k0) / g.length_m, ds)
        return _placed(g, local, turn)
    if g.kind == "poly3":
        return _poly3(g, ds)
    if g.kind == "paramPoly3":
        p = ds / g.length_m if g.param("pRange") == 1.0 else ds
        u = _cubic(p, g.param("aU"), g.param("bU"), g.param("cU"), g.param("dU"))
        v = _cubic(p, g.param("aV"), g.param("bV"), g.param("cV"), g.param("dV"))
        du = g.param("bU") + 2 * g.param("cU") * p + 3 * g.param("dU") * p**2
        dv = g.param("bV") + 2 * g.param("cV") * p + 3 * g.param("dV") * p**2
        return _placed(g, np.stack([u, v], axis=1), np.arctan2(dv, du))
    raise AssertionError(g.kind)


def spiral_xy(k0_per_m: float, rate_per_m2: float, ds_m: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray]:
    """(N, 2) points and (N,) heading change of a clothoid starting at the origin along +x
    with curvature ``k0 + rate * s``: the heading is ``k0 s + rate s^2 / 2`` and the position
    its Fresnel integral (``scipy.special.fresnel``; a straight line or arc when
    ``rate == 0``)."""
    ds = np.asarray(ds_m, dtype=np.float64)
    turn = k0_per_m * ds + 0.5 * rate_per_m2 * ds**2
    if rate_per_m2 == 0.0:
        if k0_per_m == 0.0:
            return np.stack([ds, np.zeros_like(ds)], axis=1), turn
        k = k0_per_m
        return np.stack([np.sin(k * ds) / k, (1.0 - np.cos(k * ds)) / k], axis=1), turn
    sign = 1.0 if rate_per_m2 > 0 else -1.0  # a negative rate is the mirror image in y
    rate, k0 = abs(rate_per_m2), sign * k0_per_m
    scale = np.sqrt(np.pi / rate)
    # heading k0 s + rate s^2 / 2 = (pi / 2) t^2 - phi, t = (s + k0 / rate) / scale
    t0 = k0 / rate / scale
    phi = 0.5 * k0**2 / rate
    s_t, c_t = fresnel(t0 + ds / scale)
    s_0, c_0 = fresnel(t0)
    dc, dsn = scale * (c_t - c_0), scale * (s_t - s_0)
    x = np.cos(phi) * dc + np.sin(phi) * dsn
    y = np.cos(phi) * dsn - np.sin(phi) * dc
    return np.stack([x, sign * y], axis=1), turn


def lane_lines(network: RoadNetwork, lane_types: tuple[str, ...] = ("driving",),
               step_m: float = SAMPLE_STEP_M) -> list[LaneLine]:
    """The centre line of every lane of ``lane_types`` in every section of every road,
    sampled at most ``step_m`` apart (both ends included), z from the elevation profile,
    in the file's frame after the header's offset."""
    out = []
    for road in network.roads:
        ends = [sec.s_m for sec in road.sections[1:]] + [road.length_m]
        for sec, end in zip(road.sections, ends):
            if end - sec.s_m <= 0:
                continue
            s = np.linspace(sec.s_m, end, max(2, int(np.ceil((end - sec.s_m) / step_m)) + 1))
            xy, hdg = reference_points(road, s)
            centre = _evaluate(road.lane_offset, s)
            z = _evaluate(road.elevation, s)
            normal = np.stack([-np.sin(hdg), np.cos(hdg)], axis=1)
            for lane in sec.lanes:
                if lane.type not in lane_types or lane.id == 0:
                    continue
                t = centre + _lane_centre_offset(sec, lane, s - sec.s_m)
                pts = np.column_stack([xy + t[:, None] * normal, z])
                out.append(LaneLine(road.id, lane.id, lane.type,
                                    *_offset_frame(network, pts, hdg)))
    return out


def _lane_centre_offset(sec: LaneSection, lane: Lane, ds: np.ndarray) -> np.ndarray:
    """Signed distance (left positive) from the centre lane to ``lane``'s centre."""
    side = 1 if lane.id > 0 else -1
    inner = [x for x in sec.lanes if x.id * side > 0 and abs(x.id) < abs(lane.id)]
    total = sum((_evaluate(x.widths, ds) for x in inner), np.zeros_like(ds))
    return side * (total + 0.5 * _evaluate(lane.widths, ds))


def _offset_frame(network: RoadNetwork, pts: np.ndarray, hdg: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Points and headings after the header's ``offset`` (rotate by its hdg, then shift)."""
    x, y, z, rot = network.offset
    if (x, y, z, rot) == (0.0, 0.0, 0.0, 0.0):
        return pts, hdg
    c, s = np.cos(rot), np.sin(rot)
    out = pts.copy()
    out[:, 0] = c * pts[:, 0] - s * pts[:, 1] + x
    out[:, 1] = s * pts[:, 0] + c * pts[:, 1] + y
    out[:, 2] += z
    return out, hdg + rot


def _evaluate(records: tuple[Cubic, ...], s_m: np.ndarray) -> np.ndarray:
    """The piecewise cubic ``records`` at ``s_m``; 0 where none applies."""
    s_m = np.asarray(s_m, dtype=np.float64)
    out = np.zeros_like(s_m)
    if not records:
        return out
    starts = np.array([r.s_m for r in records])
    which = np.searchsorted(starts, s_m, side="right") - 1
    for k in np.unique(which[which >= 0]):
        r = records[k]
        out[which == k] = _cubic(s_m[which == k] - r.s_m, r.a, r.b, r.c, r.d)
    return out


def _cubic(x, a, b, c, d):
    return a + x * (b + x * (c + x * d))


def _placed(g: Geometry, local: np.ndarray, turn: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    c, s = np.cos(g.hdg_rad), np.sin(g.hdg_rad)
    xy = np.stack([g.x_m + c * local[:, 0] - s * local[:, 1],
                   g.y_m + s * local[:, 0] + c * local[:, 1]], axis=1)
    return xy, g.hdg_rad + turn


def _poly3(g: Geometry, ds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """v(u) = a + b u + c u^2 + d u^3; u where the arc length reaches ``ds`` (dense table)."""
    a, b, c, d = (g.param(k) for k in "abcd")
    u = np.linspace(0.0, g.length_m, 2048)  # u <= arc length, so u never needs to exceed it
    slope = b + 2 * c * u + 3 * d * u**2
    ds_du = np.sqrt(1.0 + slope**2)
    arc = np.concatenate([[0.0], np.cumsum(0.5 * (ds_du[1:] + ds_du[:-1]) * np.diff(u))])
    uq = np.interp(ds, arc, u)
    v = _cubic(uq, a, b, c, d)
    return _placed(g, np.stack([uq, v], axis=1), np.arctan(b + 2 * c * uq + 3 * d * uq**2))


def _road(path: Path, r) -> Road:
    rid = r.get("id", "?")
    records = r.findall("planView/geometry")
    if not records:
        raise OpenDriveError(f"{path}: road {rid} has no planView geometry")
    geometry = []
    for g in records:
        kinds = [ch for ch in g if isinstance(ch.tag, str)]
        if len(kinds) != 1 or kinds[0].tag not in ("line", "arc", "spiral", "poly3",
                                                   "paramPoly3"):
            raise OpenDriveError(f"{path}: road {rid}: geometry at s={g.get('s')} is "
                                 f"{[k.tag for k in kinds]}, not one of line, arc, spiral, "
                                 "poly3, paramPoly3")
        k = kinds[0]
        params = tuple(sorted(
            (name, 1.0 if v == "normalized" else 0.0 if v == "arcLength" else float(v))
            for name, v in k.attrib.items()))
        geometry.append(Geometry(_f(g, "s"), _f(g, "x"), _f(g, "y"), _f(g, "hdg"),
                                 _f(g, "length"), k.tag, params))
    sections = tuple(
        LaneSection(_f(sec, "s"), tuple(
            Lane(int(lane.get("id")), lane.get("type", "none"),
                 tuple(_cubic_record(w, "sOffset") for w in lane.findall("width")))
            for side in ("left", "right") for lane in sec.findall(f"{side}/lane")))
        for sec in r.findall("lanes/laneSection"))
    return Road(rid, r.get("junction", "-1"), _f(r, "length"), tuple(geometry),
                tuple(_cubic_record(e, "s") for e in r.findall("elevationProfile/elevation")),
                tuple(_cubic_record(o, "s") for o in r.findall("lanes/laneOffset")), sections)


def _cubic_record(e, start: str) -> Cubic:
    return Cubic(_f(e, start), _f(e, "a"), _f(e, "b"), _f(e, "c"), _f(e, "d"))


def _f(e, name: str) -> float:
    return float(e.get(name, 0.0))
