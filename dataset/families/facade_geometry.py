"""A planar wall with rectangular openings (windows, doors) -> labelled planar faces.

A wall lies over one footprint edge p0 -> p1 and is described in wall
coordinates: u metres along the edge from p0, v metres up from the ground,
w metres along the outward normal. Each opening is a hole in the wall face,
closed by four reveal quads (class of the opening, facade 0) and a pane
recessed ``depth_m`` behind the facade plane (class of the opening, the wall's
facade). A *contact* is a hole where an attached solid (a balcony slab) covers
the wall; that solid closes it. The truth of a wall (gross, window, door,
contact areas) is computed from these parameters, not from the mesh.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from shapely.geometry import Polygon, box

from dataset.families.polygon_mesh import PlanarFace
from envelope.classes import NO_FACADE, SemanticClass
from envelope.polygons import polygon_area

MIN_GAP_M = 0.05
"""Smallest distance between two openings, or an opening and the wall edge: holes must not
touch, or the wall face stops being a polygon with separate holes."""

OpeningKind = Literal["window", "door"]


@dataclass(frozen=True)
class WallFrame:
    """Wall coordinates over the footprint edge p0 -> p1 (world x/y metres), ground at z = 0.

    The outward normal is to the right of p0 -> p1 (footprints are counter-clockwise).
    """

    p0_xy: tuple[float, float]
    p1_xy: tuple[float, float]

    def __post_init__(self) -> None:
        if self.length_m <= 0:
            raise ValueError(f"wall edge {self.p0_xy} -> {self.p1_xy} has zero length")

    @property
    def length_m(self) -> float:
        return float(np.hypot(self.p1_xy[0] - self.p0_xy[0], self.p1_xy[1] - self.p0_xy[1]))

    @property
    def u_axis(self) -> np.ndarray:
        """(3,) unit vector along the wall."""
        d = np.subtract(self.p1_xy, self.p0_xy) / self.length_m
        return np.array([d[0], d[1], 0.0])

    @property
    def normal(self) -> np.ndarray:
        """(3,) outward unit normal."""
        u = self.u_axis
        return np.array([u[1], -u[0], 0.0])

    def points_m(self, uvw: np.ndarray) -> np.ndarray:
        """World points of wall coordinates.

        Parameters
        ----------
        uvw : (n, 2) or (n, 3) float
            u along the wall, v up, optional w along the outward normal, metres.

        Returns
        -------
        (n, 3) float64 world points. The ends (u = 0, u = length) reproduce p0 and p1
        bit for bit, so neighbouring walls and roofs share their corner vertices exactly.
        """
        uvw = np.atleast_2d(np.asarray(uvw, dtype=np.float64))
        t = uvw[:, 0] / self.length_m
        p0, p1 = np.asarray(self.p0_xy, float), np.asarray(self.p1_xy, float)
        xy = (1.0 - t)[:, None] * p0 + t[:, None] * p1
        out = np.column_stack([xy, uvw[:, 1]])
        if uvw.shape[1] == 3:
            out[:, :2] += uvw[:, 2:3] * self.normal[:2]
        return out


@dataclass(frozen=True)
class Opening:
    """A rectangular window or door: u0 < u1 along the wall, v0 < v1 up, reveal depth, metres."""

    kind: OpeningKind
    u0_m: float
    v0_m: float
    u1_m: float
    v1_m: float
    depth_m: float = 0.06

    def __post_init__(self) -> None:
        if self.kind not in ("window", "door"):
            raise ValueError(f"opening kind must be 'window' or 'door', got {self.kind!r}")
        if not (self.u1_m > self.u0_m and self.v1_m > self.v0_m):
            raise ValueError(
                f"{self.kind} ({self.u0_m}, {self.v0_m})-({self.u1_m}, {self.v1_m}) has no area; "
                "give u0 < u1 and v0 < v1"
            )
        if not 0 < self.depth_m <= 0.5:
            raise ValueError(f"reveal depth must be in (0, 0.5] m, got {self.depth_m}")

    @property
    def area_m2(self) -> float:
        return (self.u1_m - self.u0_m) * (self.v1_m - self.v0_m)

    def rect(self) -> Polygon:
        return box(self.u0_m, self.v0_m, self.u1_m, self.v1_m)


@dataclass(frozen=True)
class WallSpec:
    """One planar wall of a facade: its outline in wall coordinates, openings and contacts.

    ``outline_uv`` is an (n, 2) simple polygon in (u, v) metres whose edges on
    u = 0 and u = length meet the neighbouring walls; ``contacts_uv`` are
    (u0, v0, u1, v1) rectangles covered by attached solids.
    """

    frame: WallFrame
    facade_id: int
    outline_uv: np.ndarray
    openings: tuple[Opening, ...] = ()
    contacts_uv: tuple[tuple[float, float, float, float], ...] = field(default=())

    def __post_init__(self) -> None:
        outline = np.asarray(self.outline_uv, dtype=np.float64)
        if outline.ndim != 2 or outline.shape[1] != 2 or len(outline) < 3:
            raise ValueError(f"wall outline must have shape (n >= 3, 2), got {outline.shape}")
        if self.facade_id < 1:
            raise ValueError(f"a wall needs a facade id >= 1, got {self.facade_id}")
        object.__setattr__(self, "outline_uv", outline)
        validate_wall(self)

    @property
    def height_m(self) -> float:
        return float(self.outline_uv[:, 1].max())

    def gross_area_m2(self) -> float:
        """Area of the outline (shoelace), openings and contacts included."""
        return polygon_area(self.outline_uv)

    def opening_area_m2(self, kind: OpeningKind) -> float:
        return float(sum(o.area_m2 for o in self.openings if o.kind == kind))

    def contact_area_m2(self) -> float:
        return float(sum((c[2] - c[0]) * (c[3] - c[1]) for c in self.contacts_uv))

    def wall_area_m2(self) -> float:
        """Opaque wall area: gross minus windows, doors and contacts."""
        return (
            self.gross_area_m2()
            - self.opening_area_m2("window")
            - self.opening_area_m2("door")
            - self.contact_area_m2()
        )


def rectangle_outline(width_m: float, height_m: float) -> np.ndarray:
    """(4, 2) outline of a rectangular wall, counter-clockwise in (u, v)."""
    return np.array([[0.0, 0.0], [width_m, 0.0], [width_m, height_m], [0.0, height_m]])


def validate_wall(spec: WallSpec) -> None:
    """Raise ValueError unless every opening and contact lies inside the wall and apart.

    Holes keep :data:`MIN_GAP_M` from the outline and from each other.
    """
    outline = Polygon(spec.outline_uv)
    if not outline.is_valid or outline.area <= 0:
        raise ValueError(f"wall outline of facade {spec.facade_id} is not a simple polygon")
    u = spec.outline_uv[:, 0]
    if not (np.isclose(u.min(), 0.0) and np.isclose(u.max(), spec.frame.length_m)):
        raise ValueError(
            f"wall outline of facade {spec.facade_id} spans u in [{u.min()}, {u.max()}], "
            f"but the wall edge is {spec.frame.length_m} m long"
        )
    inner = outline.buffer(-MIN_GAP_M, join_style="mitre")
    rects = [(f"{o.kind} at u={o.u0_m:.2f} v={o.v0_m:.2f}", o.rect()) for o in spec.openings]
    for c in spec.contacts_uv:
        if not (c[2] > c[0] and c[3] > c[1]):
            raise ValueError(f"contact rectangle {c} has no area; give u0 < u1 and v0 < v1")
        rects.append((f"contact at u={c[0]:.2f} v={c[1]:.2f}", box(*c)))
    for name, rect in rects:
        if not inner.contains(rect):
            raise ValueError(
                f"{name} ({rect.bounds}) does not fit in facade {spec.facade_id}'s wall "
                f"(width {spec.frame.length_m:.3f} m, height {spec.height_m:.3f} m) with a "
                f"{MIN_GAP_M} m margin; make it smaller or move it inside"
            )
    if len(rects) > 1:
        b = np.array([r.bounds for _, r in rects])
        near = (
            (b[:, None, 0] < b[None, :, 2] + MIN_GAP_M)
            & (b[None, :, 0] < b[:, None, 2] + MIN_GAP_M)
            & (b[:, None, 1] < b[None, :, 3] + MIN_GAP_M)
            & (b[None, :, 1] < b[:, None, 3] + MIN_GAP_M)
        )
        np.fill_diagonal(near, False)
        if near.any():
            i, j = np.argwhere(near)[0]
            raise ValueError(
                f"{rects[i][0]} and {rects[j][0]} on facade {spec.facade_id} are closer than "
                f"{MIN_GAP_M} m; space the openings further apart or make them smaller"
            )


def _rect_uv(u0: float, v0: float, u1: float, v1: float) -> np.ndarray:
    return np.array([[u0, v0], [u1, v0], [u1, v1], [u0, v1]])


def wall_faces(spec: WallSpec) -> list[PlanarFace]:
    """Planar faces of one wall: the wall with holes, and each opening's reveal and pane."""
    frame = spec.frame
    normal = frame.normal
    holes = [_rect_uv(o.u0_m, o.v0_m, o.u1_m, o.v1_m) for o in spec.openings]
    holes += [_rect_uv(*c) for c in spec.contacts_uv]
    rings = tuple(frame.points_m(r) for r in [spec.outline_uv, *holes])
    faces = [PlanarFace(rings, normal, SemanticClass.WALL, spec.facade_id)]
    up = np.array([0.0, 0.0, 1.0])
    for o in spec.openings:
        label = SemanticClass.WINDOW if o.kind == "window" else SemanticClass.DOOR
        corners = _rect_uv(o.u0_m, o.v0_m, o.u1_m, o.v1_m)
        front = frame.points_m(corners)
        back = frame.points_m(np.column_stack([corners, np.full(4, -o.depth_m)]))
        faces.append(PlanarFace((back,), normal, label, spec.facade_id))
        # Reveal sides in corner order: sill, right jamb, head, left jamb (normals point inward).
        side_normals = (up, -frame.u_axis, -up, frame.u_axis)
        for k, side_normal in enumerate(side_normals):
            nxt = (k + 1) % 4
            ring = np.stack([front[k], front[nxt], back[nxt], back[k]])
            faces.append(PlanarFace((ring,), side_normal, label, NO_FACADE))
    return faces


def window_grid(
    width_m: float,
    floors: int,
    floor_height_m: float,
    *,
    columns: int,
    window_width_m: float,
    window_height_m: float,
    sill_height_m: float,
    margin_m: float,
    depth_m: float,
    first_floor: int = 0,
) -> list[Opening]:
    """A regular grid of windows: ``columns`` per floor, centred in equal bays between margins.

    Floors ``first_floor .. floors - 1`` get windows; floor k's sill is at
    ``k * floor_height_m + sill_height_m``.

    Raises
    ------
    ValueError
        If the grid does not fit: no floors or columns, windows wider than their bay or
        taller than the floor, margins wider than the wall.
    """
    if floors < 1 or columns < 1:
        raise ValueError(f"a window grid needs floors, columns >= 1, got {floors}, {columns}")
    if min(window_width_m, window_height_m, floor_height_m, width_m) <= 0:
        raise ValueError("window size, floor height and wall width must be > 0 m")
    if margin_m < 0 or sill_height_m < MIN_GAP_M:
        raise ValueError(f"margin must be >= 0 and sill height >= {MIN_GAP_M} m")
    bay_m = (width_m - 2 * margin_m) / columns
    if window_width_m > bay_m - MIN_GAP_M:
        raise ValueError(
            f"{columns} windows of {window_width_m:.3f} m do not fit in a {width_m:.3f} m wall "
            f"with {margin_m:.3f} m margins (bay {bay_m:.3f} m); use fewer columns, narrower "
            "windows or smaller margins"
        )
    if sill_height_m + window_height_m > floor_height_m - MIN_GAP_M:
        raise ValueError(
            f"sill {sill_height_m:.3f} m + window {window_height_m:.3f} m exceed the floor height "
            f"{floor_height_m:.3f} m (minus {MIN_GAP_M} m); use lower windows or taller floors"
        )
    openings = []
    for k in range(first_floor, floors):
        v0 = k * floor_height_m + sill_height_m
        for c in range(columns):
            centre = margin_m + (c + 0.5) * bay_m
            openings.append(
                Opening("window", centre - window_width_m / 2, v0, centre + window_width_m / 2,
                        v0 + window_height_m, depth_m)
            )
    return openings


def drop_near(openings: list[Opening], keep_clear: list[Opening]) -> list[Opening]:
    """``openings`` without those closer than :data:`MIN_GAP_M` to any of ``keep_clear``."""
    clear = [o.rect().buffer(MIN_GAP_M, join_style="mitre") for o in keep_clear]
    return [o for o in openings if not any(c.intersects(o.rect()) for c in clear)]
