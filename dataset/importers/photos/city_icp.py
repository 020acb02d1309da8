"""The refinement of a city-model fit: trimmed point-to-plane ICP with scale, about the
vertical (docs/importing.md, section 9).

The photos' levelled sparse points ``p`` (z up, any scale) go to the city model's frame by
``x = scale * turn_z(heading) @ p + shift_m`` (:class:`PlacedSimilarity`): five unknowns, up
being known already. The model's surfaces are sampled every :data:`SAMPLE_SPACING_M`
(:func:`surface_samples`); each point's nearest sample gives the plane it is compared with.
Each Gauss-Newton step minimises ``sum (n · (x - y) / scale)²`` (in the points' own units:
in metres, shrinking the points onto one spot would zero every residual) over the points
within the trim distance of their plane (and within it plus twice the sample spacing of
their sample), on the side of it that faces the camera nearest to them (a point is not
seen through a wall), for (log scale, heading, shift); the trim distance shrinks along
:data:`TRIMS_M`.

Walls alone leave the height free, so one more observation holds it: the points' ground
(their :data:`~dataset.importers.photos.metric_frame.GROUND_PERCENTILE` along up, a point
of the street at the building's foot) at the building's lowest ground point, z = 0, weighted
as :data:`GROUND_WEIGHT` of the inliers: roofs, sills and balconies, where the photos see
them, outweigh it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from envelope.mesh import triangle_areas_m2, triangle_normals

SAMPLE_SPACING_M = 0.5
"""The model's surfaces are sampled about this far apart (metres)."""
TRIMS_M = (4.0, 2.0, 1.0, 0.5)
"""The trim distances (metres) of the refinement, in turn; the last is the inlier distance:
a point within it of a model surface is on that surface. 0.5 m: a LoD2 wall stands within
about that of the facade it models (its sills, reveals and balconies left out)."""
STEPS_PER_TRIM = 10
"""Gauss-Newton steps at most per trim distance (it stops sooner when a step changes no
point's place by a millimetre)."""
MAX_STEP = 0.3
"""The most one step changes the log scale (35 %) or the heading (17 degrees): a step
further than that comes from a poor set of inliers and would throw the fit away."""
GROUND_WEIGHT = 0.02
"""The ground observation's weight, as a share of the inliers' count."""
SAMPLE_SEED = 0


@dataclass(frozen=True)
class PlacedSimilarity:
    """``x = scale * turn_z(heading_rad) @ p + shift_m``: levelled points to the model's
    frame; ``heading_rad`` counter-clockwise about z."""

    scale: float
    heading_rad: float
    shift_m: np.ndarray

    @property
    def turn_z(self) -> np.ndarray:
        """(3, 3) the turn about z."""
        c, s = np.cos(self.heading_rad), np.sin(self.heading_rad)
        return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])

    def apply(self, points: np.ndarray) -> np.ndarray:
        """(N, 3) levelled points in the model's frame (m)."""
        return self.scale * np.asarray(points, dtype=np.float64) @ self.turn_z.T + self.shift_m


@dataclass(frozen=True)
class SurfaceSamples:
    """Points on the model's surfaces ((S, 3), m), their triangles' unit normals ((S, 3)),
    a KD-tree of the points, which of them lie on vertical surfaces and which on the
    building's own ((S,) bool each)."""

    points_m: np.ndarray
    normals: np.ndarray
    tree: cKDTree
    vertical: np.ndarray
    own: np.ndarray


@dataclass(frozen=True)
class Residuals:
    """Each point's distance to the plane of its nearest sample ((N,) m; ``inf`` with no
    sample near), that sample ((N,) index), and whether the point is an inlier at the trim
    distance ``trim_m`` ((N,) bool)."""

    distance_m: np.ndarray
    nearest: np.ndarray
    inlier: np.ndarray
    trim_m: float


def surface_samples(triangles_m: np.ndarray, own_triangles: int,
                    spacing_m: float = SAMPLE_SPACING_M) -> SurfaceSamples:
    """Samples on (T, 3, 3) triangles, about ``spacing_m`` apart (at least one per
    triangle), drawn with a fixed seed; the first ``own_triangles`` are the building's.

    Raises
    ------
    ValueError
        No triangle with an area.
    """
    tri = np.asarray(triangles_m, dtype=np.float64)
    area = triangle_areas_m2(tri)
    keep = area > 1e-9
    if not keep.any():
        raise ValueError("the city model has no surface with an area to fit the photos to")
    own = np.arange(len(tri)) < own_triangles
    tri, area, own = tri[keep], area[keep], own[keep]
    normals = triangle_normals(tri)
    count = np.maximum(1, np.ceil(area / spacing_m ** 2).astype(np.int64))
    owner = np.repeat(np.arange(len(tri)), count)
    rng = np.random.default_rng(SAMPLE_SEED)
    u, v = rng.random(len(owner)), rng.random(len(owner))
    flip = u + v > 1.0
    u[flip], v[flip] = 1.0 - u[flip], 1.0 - v[flip]
    t = tri[owner]
    points = t[:, 0] + u[:, None] * (t[:, 1] - t[:, 0]) + v[:, None] * (t[:, 2] - t[:, 0])
    return SurfaceSamples(points, normals[owner], cKDTree(points),
                          np.abs(normals[owner, 2]) < 0.5, own[owner])


def residuals(world_m: np.ndarray, cameras_m: np.ndarray, samples: SurfaceSamples,
              trim_m: float) -> Residuals:
    """Point-to-plane distances of (N, 3) points in the model's frame; inliers are within
    ``trim_m`` of a surface that faces the camera nearest to them ((K, 3) camera centres in
    the model's frame): a point seen from behind its surface is not on it."""
    gap, nearest = samples.tree.query(world_m, distance_upper_bound=trim_m + 2 * SAMPLE_SPACING_M)
    found = np.isfinite(gap)
    distance = np.full(len(world_m), np.inf)
    j = nearest[found]
    distance[found] = np.abs(np.einsum("ij,ij->i", world_m[found] - samples.points_m[j],
                                       samples.normals[j]))
    nearest = np.where(found, nearest, 0)
    _, camera = cKDTree(cameras_m).query(world_m)
    facing = np.einsum("ij,ij->i", cameras_m[camera] - world_m, samples.normals[nearest]) > 0
    return Residuals(distance, nearest, (distance <= trim_m) & facing, trim_m)


def refine(points: np.ndarray, cameras: np.ndarray, ground_point: np.ndarray,
           samples: SurfaceSamples, start: PlacedSimilarity,
           trims_m: tuple[float, ...] = TRIMS_M) -> tuple[PlacedSimilarity, Residuals]:
    """The similarity from ``start`` refined on (N, 3) levelled ``points`` seen from (K, 3)
    levelled camera centres, and the (3,) levelled ``ground_point`` (module docstring),
    with the residuals at the last trim."""
    points = np.asarray(points, dtype=np.float64)
    fit = start
    for trim in trims_m:
        for _ in range(STEPS_PER_TRIM):
            world = fit.apply(points)
            res = residuals(world, fit.apply(cameras), samples, trim)
            if res.inlier.sum() < 6:
                return fit, res
            step = _gauss_newton_step(world[res.inlier], res.nearest[res.inlier], fit,
                                      samples, ground_point)
            if not np.all(np.isfinite(step)):  # a degenerate set of inliers: stop here
                return fit, residuals(world, fit.apply(cameras), samples, trims_m[-1])
            step[:2] = np.clip(step[:2], -MAX_STEP, MAX_STEP)
            moved = PlacedSimilarity(fit.scale * float(np.exp(step[0])),
                                     fit.heading_rad + float(step[1]), fit.shift_m + step[2:])
            change = np.abs(moved.apply(points) - world).max(axis=1)
            fit = moved
            if np.median(change) < 1e-3:
                break
    return fit, residuals(fit.apply(points), fit.apply(cameras), samples, trims_m[-1])


def _gauss_newton_step(world: np.ndarray, nearest: np.ndarray, fit: PlacedSimilarity,
                       samples: SurfaceSamples, ground_point: np.ndarray) -> np.ndarray:
    """(5,) the step in (log scale, heading, shift x, y, z) for (K, 3) inlier points
    ``world`` and their nearest samples ((K,) index). The residuals are divided by the
    scale (measured in the points' own units): in metres, shrinking the points onto one
    spot of a surface would drive every residual to zero."""
    n, y = samples.normals[nearest], samples.points_m[nearest]
    arm = world - fit.shift_m  # scale * turn @ p
    turn = np.column_stack([-arm[:, 1], arm[:, 0], np.zeros(len(arm))])  # z x arm
    jac = np.column_stack([np.einsum("ij,ij->i", n, y - fit.shift_m),
                           np.einsum("ij,ij->i", n, turn), n]) / fit.scale
    r = np.einsum("ij,ij->i", n, world - y) / fit.scale
    ground = fit.apply(ground_point[None])[0]
    w = np.sqrt(GROUND_WEIGHT * len(world)) / fit.scale
    jac = np.vstack([jac, w * np.array([-fit.shift_m[2], 0.0, 0.0, 0.0, 1.0])])
    r = np.append(r, w * ground[2])
    normal = jac.T @ jac + 1e-9 * np.eye(5)
    return np.linalg.solve(normal, -jac.T @ r)
