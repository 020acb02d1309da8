"""Street views: the frames a mobile-mapping car or a street-view service takes of a building
from the road (``--street``, the ``street`` split), placed without the truth.

**Where the car drives.** Along the building's streets (``Building.streets``: the lanes of the
source's road network, :mod:`dataset.importers.opendrive.streets`); a source without a road
network gets a stand-in (:func:`street_paths`): a path :attr:`StreetConfig.fallback_offset_m`
outside the block the building stands in (the x/y convex hulls of the building and of its
neighbours, those closer than :attr:`StreetConfig.block_gap_m` joined into one block), as a
car driving round the block.

**Where it takes frames.** A station every :attr:`StreetConfig.spacing_m` metres of each path
(:func:`street_stations`; stations closer than half that to an earlier one are dropped, so
overlapping lanes and junction connectors give one row of stations, as a street-view
service's panoramas), kept when within :attr:`StreetConfig.capture_range_m` of the
building's rough outline (its x/y bounding box: what a map footprint gives) and not under
anything (a vertical ray from the camera hits neither the
building nor a neighbour: passages, arcades, a path through a house). At each station one
frame per heading of :attr:`StreetConfig.headings_deg` (from the driving direction, left
positive), pitched up by :attr:`StreetConfig.pitch_deg`, with a
:attr:`StreetConfig.fov_deg` lens, :attr:`StreetConfig.camera_height_m` above the ground
plane.

**Which frames are kept.** Those in which the building covers at least
:attr:`StreetConfig.min_building_fraction` of a :attr:`StreetConfig.check_resolution`-pixel
render, through the neighbours when they are rendered (``context``): an image selection
from a georeferenced footprint. Nothing else of the building is read: placement reads the
streets, the mesh's vertex positions (location, outline, what is hit) and the neighbours'
meshes, never the truth, the classes or the facade ids (``tests/dataset/rendering/
test_street_views.py`` poisons them).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry import MultiPoint
from shapely.geometry.polygon import orient

from envelope.camera import Intrinsics, rays_world
from envelope.geometry.raycast import Raycaster
from envelope.mesh import LabelledMesh
from envelope.truth import Building

STREET_FRAMES_PER_BUILDING = 100
"""Street frames assumed per building before it is planned (disk and memory estimates); the
lod3 preset's buildings get 6-169, median 24, with the defaults (docs/measurements/
rendering.md, "Street views")."""


@dataclass(frozen=True)
class StreetConfig:
    """How the street capture is taken (module docstring; docs/rendering.md "Street views").

    ``camera_height_m``: above the ground plane (a car's roof-mast camera, about 2.5 m).
    ``spacing_m``: between stations along a path (mobile-mapping cars trigger a frame every
    few metres; consecutive Street View panoramas lie 5-10 m apart). ``headings_deg``:
    the frames of one station, from the driving direction, left positive: both sides
    square-on and the four obliques at 45 degrees (a rig's side and oblique cameras, or the
    crops of a panorama). ``pitch_deg``: up from horizontal, so that a 90-degree lens 6-8 m
    from a 15 m facade sees from its base to its eaves. ``fov_deg``: horizontal (= vertical)
    field of view. ``capture_range_m``: stations this close to the building's x/y bounding
    box (so a large building's far streets count too).
    ``min_building_fraction``: share of a ``check_resolution``-pixel render the building
    must cover. ``fallback_offset_m``: without streets, the path's distance from the block
    (half a street: pavement and a lane); ``block_gap_m``: outlines this close are one block.
    """

    camera_height_m: float = 2.5
    spacing_m: float = 5.0
    headings_deg: tuple[float, ...] = (90.0, -90.0, 45.0, -45.0, 135.0, -135.0)
    pitch_deg: float = 20.0
    fov_deg: float = 90.0
    capture_range_m: float = 40.0
    min_building_fraction: float = 0.05
    check_resolution: int = 64
    fallback_offset_m: float = 6.0
    block_gap_m: float = 1.0

    def __post_init__(self) -> None:
        if not 1.0 <= self.camera_height_m <= 5.0:
            raise ValueError(f"camera_height_m must be in [1, 5] m, got {self.camera_height_m}")
        if self.spacing_m <= 0 or self.capture_range_m <= 0 or self.fallback_offset_m <= 0:
            raise ValueError("spacing_m, capture_range_m and fallback_offset_m must be > 0")
        if not self.headings_deg:
            raise ValueError("headings_deg needs at least one heading")
        if not -60.0 <= self.pitch_deg <= 60.0:
            raise ValueError(f"pitch_deg must be in [-60, 60], got {self.pitch_deg}")
        if not 1.0 <= self.fov_deg <= 150.0:
            raise ValueError(f"fov_deg must be in [1, 150] degrees, got {self.fov_deg}")
        if not 0.0 <= self.min_building_fraction < 1.0 or self.check_resolution < 8:
            raise ValueError("min_building_fraction must be in [0, 1), check_resolution >= 8")

    def intrinsics(self, resolution: int) -> Intrinsics:
        """Square ``resolution``-pixel intrinsics of every street frame."""
        return Intrinsics.from_fov(resolution, resolution, self.fov_deg)


@dataclass(frozen=True)
class Stations:
    """Where the car stops: ``positions_m`` (K, 3) camera centres, ``forward`` (K, 2) unit
    driving directions (x/y)."""

    positions_m: np.ndarray
    forward: np.ndarray


def street_paths(building: Building, config: StreetConfig) -> list[np.ndarray]:
    """The x/y polylines (N, 2) the car drives: the building's streets, or without any the
    stand-in round its block (module docstring)."""
    if building.streets:
        return [s.points_m[:, :2] for s in building.streets]
    meshes = [building.mesh, *(n.mesh for n in building.context)]
    gap = 0.5 * config.block_gap_m
    hulls = [MultiPoint(m.vertices_m[:, :2]).convex_hull.buffer(gap, quad_segs=32)
             for m in meshes]
    own = hulls[0]
    block = shapely.union_all(hulls)
    parts = [p for p in getattr(block, "geoms", [block]) if p.intersects(own)]
    ring = parts[0].buffer(config.fallback_offset_m - gap, quad_segs=32)
    return [np.asarray(orient(ring, sign=1.0).exterior.coords)]


def street_stations(building: Building, config: StreetConfig) -> Stations:
    """The stations within the capture range (module docstring), before the check that
    nothing stands over them."""
    lo = building.mesh.vertices_m[:, :2].min(axis=0)
    hi = building.mesh.vertices_m[:, :2].max(axis=0)
    kept_xy: list[np.ndarray] = []
    kept_fwd: list[np.ndarray] = []
    for path in street_paths(building, config):
        xy, fwd = _along(path, config.spacing_m)
        for p, f in zip(xy, fwd):
            if np.hypot(*np.maximum(np.maximum(lo - p, p - hi), 0.0)) > config.capture_range_m:
                continue
            if kept_xy and np.min(np.hypot(*(np.array(kept_xy) - p).T)) < 0.5 * config.spacing_m:
                continue
            kept_xy.append(p)
            kept_fwd.append(f)
    xy = np.array(kept_xy).reshape(-1, 2)
    z = np.full((len(xy), 1), config.camera_height_m)
    return Stations(np.hstack([xy, z]), np.array(kept_fwd).reshape(-1, 2))


def street_views(building: Building, config: StreetConfig, *, context: bool
                 ) -> list[np.ndarray]:
    """(4, 4) ``world_from_camera`` poses of the street frames, station by station, heading
    by heading; ``context``: the neighbours hide the building in the visibility check (as
    they do in the rendered frames)."""
    stations = street_stations(building, config)
    if not len(stations.positions_m):
        return []
    everything, _ = scene_caster(building, with_neighbours=True)
    clear = everything.open_to_sky(stations.positions_m)
    seen_by, n_own = scene_caster(building, with_neighbours=context)
    k = config.intrinsics(config.check_resolution)
    poses = []
    for eye, fwd in zip(stations.positions_m[clear], stations.forward[clear]):
        for heading in config.headings_deg:
            pose = street_pose(eye, fwd, heading, config.pitch_deg)
            if _building_fraction(seen_by, n_own, k, pose) >= config.min_building_fraction:
                poses.append(pose)
    return poses


def street_pose(eye_m: np.ndarray, forward_xy: np.ndarray, heading_deg: float,
                pitch_deg: float) -> np.ndarray:
    """(4, 4) pose at ``eye_m`` looking ``heading_deg`` left of the driving direction
    ``forward_xy`` (2,), pitched up ``pitch_deg``, its image's x axis level."""
    yaw = np.arctan2(forward_xy[1], forward_xy[0]) + np.radians(heading_deg)
    pitch = np.radians(pitch_deg)
    look = np.array([np.cos(yaw) * np.cos(pitch), np.sin(yaw) * np.cos(pitch), np.sin(pitch)])
    right = np.array([np.sin(yaw), -np.cos(yaw), 0.0])
    pose = np.eye(4)
    pose[:3, 0], pose[:3, 1], pose[:3, 2] = right, np.cross(right, look), -look
    pose[:3, 3] = eye_m
    return pose


def _along(path: np.ndarray, spacing_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Points every ``spacing_m`` of arc along ``path`` (N, 2) from its start, and the unit
    direction of the segment each lies on."""
    seg = np.diff(path, axis=0)
    length = np.hypot(*seg.T)
    keep = length > 0
    seg, length, starts = seg[keep], length[keep], path[:-1][keep]
    if not len(seg):
        return np.zeros((0, 2)), np.zeros((0, 2))
    cum = np.concatenate([[0.0], np.cumsum(length)])
    s = np.arange(0.0, cum[-1] + 1e-9, spacing_m)
    k = np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(seg) - 1)
    direction = seg[k] / length[k, None]
    return starts[k] + (s - cum[k])[:, None] * direction, direction


def scene_caster(building: Building, *, with_neighbours: bool) -> tuple[Raycaster, int]:
    """A caster of the building (and its neighbours), and how many of its faces (the first
    ones) are the building's."""
    meshes = [building.mesh, *(n.mesh for n in building.context if with_neighbours)]
    if len(meshes) == 1:
        return Raycaster(building.mesh), len(building.mesh.faces)
    vertices, faces, n = [], [], 0
    for m in meshes:
        vertices.append(m.vertices_m)
        faces.append(m.faces + n)
        n += len(m.vertices_m)
    count = sum(len(f) for f in faces)
    plain = LabelledMesh(np.concatenate(vertices), np.concatenate(faces),
                         np.zeros(count, dtype=np.int64), np.zeros(count, dtype=np.int64))
    return Raycaster(plain), len(building.mesh.faces)


def _building_fraction(caster: Raycaster, n_own: int, k: Intrinsics, pose: np.ndarray
                       ) -> float:
    """Share of the pixels of a view whose first hit above the ground is the building."""
    origins, dirs = rays_world(k, pose)
    face, t = caster.first_hit(origins.reshape(-1, 3), dirs.reshape(-1, 3))
    z = origins.reshape(-1, 3)[:, 2] + np.where(np.isfinite(t), t, 0.0) * dirs.reshape(-1, 3)[:, 2]
    return float(np.mean((face >= 0) & (face < n_own) & (z >= 0.0)))

