"""Which pixels of a view belong to the photographed facade.

facade = wall | window | door pixels (DESIGN.md). A natural view often shows a
neighbouring facade too, joined to the target along the building corner.

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

from dataclasses import dataclass

import cv2
import numpy as np

from baselines.plane import Plane, fit_plane_ransac, points_camera_m
from baselines.views import ViewError
from dataset.camera import Intrinsics
from dataset.classes import FACADE_CLASSES, SemanticClass

_FACADE_LOOKUP = np.isin(np.arange(256), [int(c) for c in FACADE_CLASSES])  # uint8 id -> bool


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
    """

    wall_tolerance_m: float = 0.05
    recess_max_m: float = 0.6
    ransac_iterations: int = 64
    centre_fraction: float = 0.5
    sample_points: int = 1500
    min_centre_points: int = 50
    anchor_points: int = 32

    def __post_init__(self) -> None:
        if self.wall_tolerance_m <= 0 or self.recess_max_m < 0:
            raise ValueError("wall_tolerance_m must be > 0 and recess_max_m >= 0")
        if not 0 < self.centre_fraction <= 1:
            raise ValueError(f"centre_fraction must be in (0, 1], got {self.centre_fraction}")
        if self.ransac_iterations < 1 or self.sample_points < 3 or self.anchor_points < 1:
            raise ValueError("ransac_iterations, sample_points (>= 3) and anchor_points "
                             "must be positive")


def facade_class_mask(labels: np.ndarray) -> np.ndarray:
    """(H, W) bool: wall, window or door pixels of (H, W) class ids."""
    labels = np.asarray(labels)
    if labels.ndim != 2:
        raise ValueError(f"labels must be an (H, W) class-id image, got shape {labels.shape}")
    return _FACADE_LOOKUP[labels] if labels.dtype == np.uint8 else np.isin(
        labels, [int(c) for c in FACADE_CLASSES])


def centre_component(mask: np.ndarray) -> np.ndarray:
    """(H, W) bool: the 8-connected component of ``mask`` at the image centre.

    When the centre pixel is not in the mask, the component of the mask pixel
    nearest to the centre is taken.

    Raises
    ------
    ViewError
        If ``mask`` has no pixel.
    """
    mask = np.asarray(mask, dtype=bool)
    if not mask.any():
        raise ViewError("no facade pixels (wall, window or door) in the semantic mask")
    n, comp = cv2.connectedComponents(mask.astype(np.uint8), connectivity=8)
    h, w = mask.shape
    cy, cx = h // 2, w // 2
    label = comp[cy, cx]
    if label == 0:
        ys, xs = np.nonzero(mask)
        i = int(np.argmin((ys - cy) ** 2 + (xs - cx) ** 2))
        label = comp[ys[i], xs[i]]
    return comp == label


def isolate_facade_2ds(labels: np.ndarray) -> np.ndarray:
    """(H, W) bool mask of the target facade as 2D-S sees it (centre component)."""
    return centre_component(facade_class_mask(labels))


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
    depth = np.asarray(depth_z_m)
    if depth.shape != facade.shape:
        raise ValueError(f"depth {depth.shape} and labels {facade.shape} differ in shape")
    if not facade.any():
        raise ViewError("no facade pixels (wall, window or door) in the semantic mask")
    # Work on the facade pixels with depth only (index lists): a fraction of the image.
    ys, xs = np.nonzero(facade & (depth > 0) & (depth < np.inf))
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
    walls = np.nonzero(labels[ys, xs] == SemanticClass.WALL)[0]
    walls = walls if len(walls) else np.arange(len(ys))
    r2 = (xs[walls] + 0.5 - w / 2) ** 2 + (ys[walls] + 0.5 - h / 2) ** 2
    anchors = walls[np.argsort(r2)[: config.anchor_points]]
    try:
        plane = fit_plane_ransac(
            pts[sample], threshold_m=config.wall_tolerance_m,
            iterations=config.ransac_iterations, rng=rng, refine_points_m=pts[refine],
            anchor_points_m=pts[anchors],
        )
    except ValueError as exc:
        raise ViewError(f"no facade plane in the depth image: {exc}") from exc
    dist = plane.signed_distance_m(pts)
    is_wall = labels[ys, xs] == SemanticClass.WALL
    on_plane = np.where(
        is_wall,
        np.abs(dist) <= config.wall_tolerance_m,
        (dist <= config.wall_tolerance_m) & (dist >= -config.recess_max_m),
    )
    if not on_plane.any():
        raise ViewError("no facade pixel lies on the fitted facade plane")
    keep = np.zeros_like(facade)
    keep[ys[on_plane], xs[on_plane]] = True
    return centre_component(keep), plane


def _subsample(n: int, k: int, rng: np.random.Generator) -> np.ndarray:
    # With replacement: a few repeats do not matter and it avoids permuting n items.
    return np.arange(n) if n <= k else rng.integers(0, n, k)


def _points(xs: np.ndarray, ys: np.ndarray, depth: np.ndarray, k: Intrinsics) -> np.ndarray:
    uv = np.stack([xs + 0.5, ys + 0.5], axis=-1)
    return points_camera_m(uv, depth[ys, xs], k)
