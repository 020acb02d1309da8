"""Which pixels of a view belong to the photographed facade.

facade = wall | window | door pixels (docs/DESIGN.md). A natural view often shows a
neighbouring facade too, joined to the target along the building corner.
Occluders in front of a facade (class "other": balconies, railings) must not
split it: connectivity is taken over facade | other pixels, and the result
keeps the facade pixels of the component (a row of balconies across the whole
facade would otherwise cut it into strips).

* 2D-S sees only the mask, as the original method does: it keeps the
  8-connected facade component at the image centre (the photographer aimed at
  the facade). A neighbour that touches the target along a building corner is
  part of the same component; that is the method's limitation, kept on purpose.
* 2D-SS also has depth: it fits the dominant plane through the facade pixels
  near the image centre (RANSAC on back-projected points) and keeps the wall
  pixels on that plane and the window/door pixels on it or recessed behind it,
  then the component at the centre. The plane is anchored at the wall pixels
  nearest the image centre, so a bigger neighbouring facade does not win.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import cv2
import numpy as np

from baselines.plane import Plane, fit_plane_ransac, points_camera_m
from baselines.views import ViewError
from envelope.camera import Intrinsics
from envelope.classes import FACADE_CLASSES, SemanticClass

_MIN_FIT_PIXELS = 200  # fewer sampled pixels than this: fit to every pixel instead
_FACADE_LOOKUP = np.isin(np.arange(256), [int(c) for c in FACADE_CLASSES])  # uint8 id -> bool
_WALL_LOOKUP = np.arange(256) == SemanticClass.WALL


@dataclass(frozen=True)
class PlaneIsolationConfig:
    """How 2D-SS isolates the target facade with depth.

    ``wall_tolerance_m``: a wall pixel is on the plane if within this distance
    (covers depth quantisation and noise). ``recess_max_m``: a window or door
    pixel may lie up to this far behind the plane (reveals and recessed glass).
    ``centre_fraction``: RANSAC samples facade pixels in the central box of this
    fraction of the image width and height. ``sample_points``: at most this many
    points are sampled for RANSAC. ``anchor_points``: every RANSAC plane passes
    through one of this many wall pixels nearest the image centre.
    ``fit_stride``: the plane is fitted to every ``fit_stride``-th pixel in
    each direction (all pixels if that leaves too few); the mask is full-resolution.
    """

    wall_tolerance_m: float = 0.05
    recess_max_m: float = 0.6
    ransac_iterations: int = 64
    centre_fraction: float = 0.5
    sample_points: int = 1500
    min_centre_points: int = 50
    anchor_points: int = 32
    fit_stride: int = 4

    def __post_init__(self) -> None:
        if self.wall_tolerance_m <= 0 or self.recess_max_m < 0:
            raise ValueError("wall_tolerance_m must be > 0 and recess_max_m >= 0")
        if not 0 < self.centre_fraction <= 1:
            raise ValueError(f"centre_fraction must be in (0, 1], got {self.centre_fraction}")
        if (self.ransac_iterations < 1 or self.sample_points < 3 or self.anchor_points < 1
                or self.fit_stride < 1):
            raise ValueError("ransac_iterations, sample_points (>= 3) and anchor_points "
                             "and fit_stride must be positive")


def tolerance_for_depth_steps(config: PlaneIsolationConfig, labels: np.ndarray,
                              depth_z_m: np.ndarray, relative_step: float
                              ) -> PlaneIsolationConfig:
    """``config`` with ``wall_tolerance_m`` raised to one depth step at the facade's far
    depth (95th percentile of its pixels) when the depth is quantised relative to its
    value (``relative_step`` > 0, e.g. 1/128 for Radiance HDR): a flat wall's points then
    scatter by up to a step (32-64 m: 0.25 m), and a tighter tolerance keeps one band."""
    if relative_step <= 0:
        return config
    depth = np.asarray(depth_z_m)
    seen = depth[facade_class_mask(labels) & (depth > 0)]
    if seen.size == 0:
        return config
    step_m = relative_step * float(np.percentile(seen, 95))
    if step_m <= config.wall_tolerance_m:
        return config
    return replace(config, wall_tolerance_m=step_m)


def facade_class_mask(labels: np.ndarray) -> np.ndarray:
    """(H, W) bool: wall, window or door pixels of (H, W) class ids."""
    labels = np.asarray(labels)
    if labels.ndim != 2:
        raise ValueError(f"labels must be an (H, W) class-id image, got shape {labels.shape}")
    return _FACADE_LOOKUP[labels] if labels.dtype == np.uint8 else np.isin(
        labels, [int(c) for c in FACADE_CLASSES])


def centre_component(mask: np.ndarray, bridge: np.ndarray | None = None) -> np.ndarray:
    """(H, W) bool: the pixels of ``mask`` in its 8-connected component at the image centre.

    Components are taken over ``mask | bridge`` (pixels that connect the mask
    without belonging to it, e.g. occluders). When the centre pixel is in
    neither, the component of the mask pixel nearest to the centre is taken.

    Raises
    ------
    ViewError
        If ``mask`` has no pixel.
    """
    mask = np.asarray(mask, dtype=bool)
    if not mask.any():
        raise ViewError("no facade pixels (wall, window or door) in the semantic mask")
    joined = mask if bridge is None else mask | np.asarray(bridge, dtype=bool)
    _, comp = cv2.connectedComponents(joined.astype(np.uint8), connectivity=8)
    h, w = mask.shape
    cy, cx = h // 2, w // 2
    label = comp[cy, cx]
    if label == 0:
        ys, xs = np.nonzero(mask)
        i = int(np.argmin((ys - cy) ** 2 + (xs - cx) ** 2))
        label = comp[ys[i], xs[i]]
    return (comp == label) & mask


def occluder_mask(labels: np.ndarray) -> np.ndarray:
    """(H, W) bool: pixels of class "other" (balconies, railings), which may hide a facade."""
    return np.asarray(labels) == SemanticClass.OTHER


def isolate_facade_2ds(labels: np.ndarray) -> np.ndarray:
    """(H, W) bool mask of the target facade as 2D-S sees it (centre component)."""
    return centre_component(facade_class_mask(labels), occluder_mask(labels))


def isolate_facade_on_plane(
    labels: np.ndarray,
    depth_z_m: np.ndarray,
    intrinsics: Intrinsics,
    config: PlaneIsolationConfig,
    rng: np.random.Generator,
) -> tuple[np.ndarray, Plane]:
    """The target facade's pixels and plane, from the semantic mask and depth (2D-SS).

    Parameters
    ----------
    labels : (H, W) uint8 class ids
    depth_z_m : (H, W) float z-depth in metres, 0 = none

    Returns
    -------
    mask : (H, W) bool, the facade component on the plane at the image centre
    plane : the facade plane in the camera frame

    Raises
    ------
    ViewError
        If there are no facade pixels, no valid depth on them, or no plane.
    """
    facade = facade_class_mask(labels)
    depth = np.asarray(depth_z_m, dtype=np.float32)
    if depth.shape != facade.shape:
        raise ValueError(f"depth {depth.shape} and labels {facade.shape} differ in shape")
    if not facade.any():
        raise ViewError("no facade pixels (wall, window or door) in the semantic mask")
    ys, xs = _fit_pixels(facade, depth, config.fit_stride)
    if len(ys) < 3:
        raise ViewError("no valid depth on the facade pixels")
    pts = _points(xs, ys, depth, intrinsics)
    h, w = facade.shape
    half_w, half_h = 0.5 * config.centre_fraction * w, 0.5 * config.centre_fraction * h
    central = np.nonzero((np.abs(xs + 0.5 - w / 2) <= half_w)
                         & (np.abs(ys + 0.5 - h / 2) <= half_h))[0]
    if len(central) < config.min_centre_points:
        central = np.arange(len(ys))
    sample = central[_subsample(len(central), config.sample_points, rng)]
    refine = _subsample(len(ys), 4 * config.sample_points, rng)
    # Anchor the plane at the wall pixels nearest the image centre (where the
    # photographer aimed): the biggest plane in view may be a neighbour.
    ay, ax = _anchor_pixels(labels, depth, config.anchor_points)
    anchors_m = _points(ax, ay, depth, intrinsics)
    try:
        plane = fit_plane_ransac(
            pts[sample], threshold_m=config.wall_tolerance_m,
            iterations=config.ransac_iterations, rng=rng, refine_points_m=pts[refine],
            anchor_points_m=anchors_m,
        )
    except ValueError as exc:
        raise ViewError(f"no facade plane in the depth image: {exc}") from exc
    dist = _signed_distance_image(plane, depth, intrinsics)
    tol = np.float32(config.wall_tolerance_m)
    lowest = np.where(labels == SemanticClass.WALL, -tol, np.float32(-config.recess_max_m))
    keep = facade & (depth > 0) & (dist <= tol) & (dist >= lowest)
    if not keep.any():
        raise ViewError("no facade pixel lies on the fitted facade plane")
    return centre_component(keep, occluder_mask(labels)), plane


def _fit_pixels(facade: np.ndarray, depth: np.ndarray, stride: int) -> tuple[np.ndarray, ...]:
    """Rows and columns of facade pixels with depth on a grid of ``stride`` (all if too few)."""
    d = depth[::stride, ::stride]
    ys, xs = np.nonzero(facade[::stride, ::stride] & (d > 0) & np.isfinite(d))
    if stride > 1 and len(ys) < _MIN_FIT_PIXELS:
        return _fit_pixels(facade, depth, 1)
    return ys * stride, xs * stride


def _anchor_pixels(labels: np.ndarray, depth: np.ndarray, count: int) -> tuple[np.ndarray, ...]:
    """Rows and columns of the ``count`` wall pixels with depth nearest the image centre.

    Searched in a centred window that doubles until it holds enough; facade
    pixels of any class stand in when the view has no wall pixel with depth.
    """
    h, w = labels.shape
    cy, cx = h / 2, w / 2
    for classes in (_WALL_LOOKUP, _FACADE_LOOKUP):
        r = 8
        while True:
            y0, x0 = max(0, int(cy - r)), max(0, int(cx - r))
            window = np.s_[y0:min(h, int(cy + r) + 1), x0:min(w, int(cx + r) + 1)]
            ys, xs = np.nonzero(classes[labels[window]] & (depth[window] > 0))
            if len(ys) >= count or r > max(h, w):
                break
            r *= 2
        if len(ys):
            ys, xs = ys + y0, xs + x0
            k = min(count, len(ys))
            near = np.argpartition((ys + 0.5 - cy) ** 2 + (xs + 0.5 - cx) ** 2, k - 1)[:k]
            return ys[near], xs[near]
    return ys, xs  # empty: the caller's RANSAC reports it


def _subsample(n: int, k: int, rng: np.random.Generator) -> np.ndarray:
    # With replacement: a few repeats do not matter and it avoids permuting n items.
    return np.arange(n) if n <= k else rng.integers(0, n, k)


def _points(xs: np.ndarray, ys: np.ndarray, depth: np.ndarray, k: Intrinsics) -> np.ndarray:
    uv = np.stack([xs + 0.5, ys + 0.5], axis=-1)
    return points_camera_m(uv, depth[ys, xs], k)


def _signed_distance_image(plane: Plane, depth: np.ndarray, k: Intrinsics) -> np.ndarray:
    """(H, W) float32 signed distance to the plane of every pixel's depth point.

    The ray direction is separable in u and v, so n . dir is the sum of a row
    and a column term: no (H, W, 3) array of directions.
    """
    h, w = depth.shape
    n = plane.normal
    col = (n[0] * (np.arange(w) + 0.5 - k.cx) / k.fx - n[2]).astype(np.float32)
    row = (-n[1] * (np.arange(h) + 0.5 - k.cy) / k.fy).astype(np.float32)
    return depth * (row[:, None] + col[None, :]) - np.float32(plane.offset_m)
