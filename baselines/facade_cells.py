"""A facade's window, wall and door areas by voting on a grid of cells on its plane (2D-SS).

Each wall, window or door pixel of a view belongs to at most one facade: the one whose
plane its surface lies on (at most ``front_m`` in front of it, at most ``back_m`` behind it:
a window's glass is set back from the wall; within the facade's extent widened by
``pad_m``), the nearest where several planes qualify (the facets of a curved wall, a
corner), so no surface is counted by two facades (:func:`pixel_owners`).

Each facade's plane (:class:`baselines.plane_merge.FacadePlane`) is cut into square cells of
``cell_m`` over its extent widened by ``pad_m`` on every side. Each view in front of the
plane (seeing it at an angle of incidence whose cosine is at least ``min_view_cos``) looks
up the pixel each cell centre projects to, and votes:

- the pixel's class where the pixel belongs to this facade; "none" where its surface lies
  on the plane but it belongs to no facade (roof, balcony, anything but wall, window or
  door);
- "none" where the pixel has no depth or its surface lies farther behind the plane, or
  behind it on another facade (the cell is off the facade: the view looks past it);
- nothing where the surface lies farther in front, or in front on another facade
  (something hides the cell).

A cell's class is the majority of its votes (a tie goes to "none"); cells without a vote
are not counted. Each area is its cells times ``cell_m``², so a part of the facade seen by
many views is counted once.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from baselines.plane_merge import FacadePlane
from baselines.posed_views import PosedView
from baselines.view_planes import UP
from envelope.camera import project_world_to_image
from envelope.classes import SemanticClass
from envelope.wwr import ClassAreas

NONE, WALL, WINDOW, DOOR = range(4)  # vote indices
_VOTE_OF_CLASS = np.zeros(256, dtype=np.int64)
_VOTE_OF_CLASS[[SemanticClass.WALL, SemanticClass.WINDOW, SemanticClass.DOOR]] = [WALL, WINDOW,
                                                                                  DOOR]


@dataclass(frozen=True)
class CellConfig:
    """The cell grid and its voting (module docstring); chosen on the tiny preset."""

    cell_m: float = 0.1
    pad_m: float = 0.5
    front_m: float = 0.3
    back_m: float = 0.6
    min_view_cos: float = 0.2

    def __post_init__(self) -> None:
        if not (self.cell_m > 0 and self.pad_m >= 0 and self.front_m > 0 and self.back_m > 0):
            raise ValueError("cell_m, front_m and back_m must be > 0 and pad_m >= 0")
        if not 0 < self.min_view_cos <= 1:
            raise ValueError("min_view_cos must be in (0, 1]")


@dataclass(frozen=True)
class CellAreas:
    """What the cells of one facade measured: ``areas`` (m²); ``centre_m`` (3,) the mean of
    its facade cells' centres (world); ``width_m``/``height_m`` their extent along the plane
    and in height; ``views`` how many views voted wall, window or door on a cell."""

    areas: ClassAreas
    centre_m: np.ndarray
    width_m: float
    height_m: float
    views: int


def cell_centres_m(facade: FacadePlane, config: CellConfig) -> tuple[np.ndarray, np.ndarray,
                                                                      np.ndarray]:
    """(M, 3) world centres of the facade's cells and their (M,) coordinates along the plane
    and in height (m)."""
    def centres(lo: float, hi: float) -> np.ndarray:
        lo, hi = lo - config.pad_m, hi + config.pad_m
        n = max(1, int(np.ceil((hi - lo) / config.cell_m)))
        return lo + (np.arange(n) + 0.5) * config.cell_m

    s, z = np.meshgrid(centres(*facade.s_range_m), centres(*facade.z_range_m), indexing="ij")
    s, z = s.ravel(), z.ravel()
    points = facade.normal * facade.offset_m + s[:, None] * facade.along + z[:, None] * UP
    return points, s, z


def pixel_owners(view: PosedView, facades: list[FacadePlane], config: CellConfig) -> np.ndarray:
    """(H, W) int: for each wall, window or door pixel, the index in ``facades`` of the facade
    its surface lies on (within ``front_m`` in front to ``back_m`` behind its plane and within
    its extent widened by ``pad_m``), the nearest plane where several qualify; -1 for none."""
    points = view.world_points_m()
    facade_px = view.facade_pixels()
    best = np.full(facade_px.shape, np.inf)
    owner = np.full(facade_px.shape, -1, dtype=np.int64)
    for k, f in enumerate(facades):
        d = points @ f.normal - f.offset_m
        s = points @ f.along
        on = (facade_px & (d <= config.front_m) & (d >= -config.back_m)
              & (s >= f.s_range_m[0] - config.pad_m) & (s <= f.s_range_m[1] + config.pad_m)
              & (points[..., 2] >= f.z_range_m[0] - config.pad_m)
              & (points[..., 2] <= f.z_range_m[1] + config.pad_m) & (np.abs(d) < best))
        best[on] = np.abs(d[on])
        owner[on] = k
    return owner


def cell_votes(facade: FacadePlane, index: int, points_m: np.ndarray, view: PosedView,
               owners: np.ndarray, config: CellConfig) -> tuple[np.ndarray, np.ndarray]:
    """One view's votes on the cells at ``points_m`` (M, 3) of ``facades[index]``: the cells'
    indices (V,) and their votes (V,) (none, wall, window or door), from the view's
    :func:`pixel_owners` ``owners`` (a pixel on another facade's plane votes "none" behind
    this plane and nothing in front of it)."""
    h = float(facade.normal @ view.camera_m) - facade.offset_m  # camera to plane, m
    if h <= 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    seen = h / np.linalg.norm(view.camera_m - points_m, axis=1) >= config.min_view_cos
    idx = np.flatnonzero(seen)
    k = view.intrinsics
    uv, z = project_world_to_image(points_m[idx], k, view.frame.world_from_camera)
    inside = (z > 0) & (uv[:, 0] >= 0) & (uv[:, 0] < k.width) & (uv[:, 1] >= 0) & (
        uv[:, 1] < k.height)
    idx, uv, z = idx[inside], uv[inside], z[inside]
    col, row = uv[:, 0].astype(np.int64), uv[:, 1].astype(np.int64)
    d = view.depth_z_m[row, col].astype(np.float64)
    behind_m = (d / z - 1.0) * h  # how far behind the plane the pixel's surface lies
    owner = owners[row, col]
    on_plane = (d > 0) & (behind_m >= -config.front_m) & (behind_m <= config.back_m)
    elsewhere = on_plane & (owner >= 0) & (owner != index)
    past = (d <= 0) | (behind_m > config.back_m) | (elsewhere & (behind_m >= 0))
    mine = on_plane & ~elsewhere
    vote = np.where(mine & (owner == index), _VOTE_OF_CLASS[view.labels[row, col]], NONE)
    keep = mine | past
    return idx[keep], vote[keep]


def measure_facades(facades: list[FacadePlane], views: list[PosedView],
                    config: CellConfig) -> list[CellAreas | None]:
    """Each facade's class areas by cell voting (module docstring), in the order of
    ``facades``; ``None`` for one with no wall, window or door cell."""
    grids = [cell_centres_m(f, config) for f in facades]
    votes = [np.zeros((len(g[0]), 4), dtype=np.int64) for g in grids]
    voters = [0] * len(facades)
    for view in views:
        owners = pixel_owners(view, facades, config)
        for k, (facade, (points, _, _)) in enumerate(zip(facades, grids)):
            idx, vote = cell_votes(facade, k, points, view, owners, config)
            np.add.at(votes[k], (idx, vote), 1)
            voters[k] += bool(np.any(vote != NONE))
    return [_areas(v, g, n, config) for v, g, n in zip(votes, grids, voters)]


def measure_facade_cells(facade: FacadePlane, views: list[PosedView],
                         config: CellConfig) -> CellAreas | None:
    """One facade's class areas by cell voting, as if it were the only one."""
    return measure_facades([facade], views, config)[0]


def _areas(votes: np.ndarray, grid: tuple[np.ndarray, np.ndarray, np.ndarray], voters: int,
           config: CellConfig) -> CellAreas | None:
    points, s, z = grid
    cls = np.where(votes.sum(axis=1) > 0, np.argmax(votes, axis=1), NONE)
    on = cls != NONE
    if not on.any():
        return None
    cell_m2 = config.cell_m ** 2
    areas = ClassAreas(window_m2=float(np.count_nonzero(cls == WINDOW)) * cell_m2,
                       wall_m2=float(np.count_nonzero(cls == WALL)) * cell_m2,
                       door_m2=float(np.count_nonzero(cls == DOOR)) * cell_m2)
    return CellAreas(areas, points[on].mean(axis=0),
                     float(np.ptp(s[on])) + config.cell_m, float(np.ptp(z[on])) + config.cell_m,
                     voters)
