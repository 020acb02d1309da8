"""One facade from the planes several views found on it: merge view planes across views.

Two view planes (:class:`baselines.view_planes.ViewPlane`) are the same facade when their
normals agree within ``angle_deg``, each one's inliers lie within ``offset_m`` of the other
plane on average, and their extents along the plane overlap or leave a gap of at most
``gap_m``. The relation is closed transitively (union-find): each group is one facade, a
:class:`FacadePlane` whose normal and offset are its members' averaged.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from baselines.view_planes import UP, ViewPlane


@dataclass(frozen=True)
class MergeConfig:
    """When two view planes are one facade (module docstring); chosen on the tiny preset."""

    angle_deg: float = 10.0
    offset_m: float = 0.5
    gap_m: float = 1.0

    def __post_init__(self) -> None:
        if not (0 < self.angle_deg < 90 and self.offset_m > 0 and self.gap_m >= 0):
            raise ValueError("angle_deg must be in (0, 90), offset_m > 0 and gap_m >= 0")


@dataclass(frozen=True)
class FacadePlane:
    """A facade found in several views: the vertical plane ``normal . x = offset_m`` (world).

    ``normal`` (3,) horizontal, outward (towards the cameras that saw it); ``s_range_m``
    and ``z_range_m`` the extent of its members' inliers along :attr:`along` and in height;
    ``members`` the view planes it was merged from.
    """

    normal: np.ndarray
    offset_m: float
    s_range_m: tuple[float, float]
    z_range_m: tuple[float, float]
    members: tuple[ViewPlane, ...]

    @property
    def along(self) -> np.ndarray:
        return np.cross(UP, self.normal)

    @property
    def view_indices(self) -> frozenset[int]:
        return frozenset(m.view_index for m in self.members)

    @property
    def centre_m(self) -> np.ndarray:
        """(3,) centre of its extent on the plane."""
        s = 0.5 * sum(self.s_range_m)
        z = 0.5 * sum(self.z_range_m)
        return self.normal * self.offset_m + self.along * s + UP * z


def same_facade(a: ViewPlane, b: ViewPlane, config: MergeConfig) -> bool:
    """Whether two view planes are one facade (module docstring)."""
    if a.normal @ b.normal < np.cos(np.radians(config.angle_deg)):
        return False
    for p, q in ((a, b), (b, a)):
        if abs(float(np.mean(q.points_m @ p.normal)) - p.offset_m) > config.offset_m:
            return False
    lo_a, hi_a = a.s_range_m
    lo_b, hi_b = _s_range_on(b, a.along)
    return max(lo_a, lo_b) - min(hi_a, hi_b) <= config.gap_m


def merge_view_planes(planes: list[ViewPlane], config: MergeConfig) -> list[FacadePlane]:
    """Group the view planes of all views into facades (module docstring), in the order of
    their first member."""
    parent = list(range(len(planes)))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for i in range(len(planes)):
        for j in range(i + 1, len(planes)):
            if root(i) != root(j) and same_facade(planes[i], planes[j], config):
                parent[root(j)] = root(i)
    groups: dict[int, list[ViewPlane]] = {}
    for i, plane in enumerate(planes):
        groups.setdefault(root(i), []).append(plane)
    return [facade_plane(members) for members in groups.values()]


def facade_plane(members: list[ViewPlane]) -> FacadePlane:
    """The plane of a group: its members' normals and offsets averaged, each weighted by its
    inlier count, with the union of their extents."""
    weights = np.array([m.n_points for m in members], dtype=np.float64)
    normal = weights @ np.array([m.normal for m in members])
    normal[2] = 0.0
    normal /= np.linalg.norm(normal)
    offset = float(weights @ [np.mean(m.points_m @ normal) for m in members] / weights.sum())
    along = np.cross(UP, normal)
    s = np.array([_s_range_on(m, along) for m in members])
    z = np.array([m.z_range_m for m in members])
    return FacadePlane(normal, offset, (float(s[:, 0].min()), float(s[:, 1].max())),
                       (float(z[:, 0].min()), float(z[:, 1].max())), tuple(members))


def _s_range_on(plane: ViewPlane, along: np.ndarray) -> tuple[float, float]:
    """A view plane's extent measured along another (nearly parallel) plane's ``along``."""
    ends = [plane.normal * plane.offset_m + plane.along * s for s in plane.s_range_m]
    s = sorted(float(e @ along) for e in ends)
    return s[0], s[1]
