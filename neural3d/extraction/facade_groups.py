"""Class areas of a semantic mesh's triangles and its facade groups, found without the truth.

Areas follow the paper: each triangle's area is shared among classes by the
fraction of its three vertices in each class (a triangle with two window
vertices and one wall vertex gives 2/3 of its area to window, 1/3 to wall).

Facades are found from the horizontal direction of the facade triangles' normals:

1. facade triangles (some wall/window/door area) whose normal is within
   ``facade_max_tilt_deg`` of horizontal take part;
2. their azimuths go into an area-weighted circular histogram, smoothed with a
   Gaussian; peaks are taken greedily, highest first, each suppressing its
   neighbours within ``min_facade_separation_deg``;
3. every triangle joins its nearest peak; within a peak, triangles are split
   into parallel planes where their offsets along the peak normal leave a gap
   larger than ``plane_gap_m`` (the two parallel walls of an L-shape, a bay's
   front and the wall beside it, a set-back front);
4. within a plane, triangles are split where their positions along the plane
   (horizontal, the centroids' tangent coordinate) leave a gap larger than
   ``plane_extent_gap_m``: two facades of one plane that stand apart (the
   wall left and right of a bay, the fronts of two bays) are facades of their own;
5. groups smaller than ``min_facade_area_m2`` or ``min_facade_area_fraction`` of
   the grouped area (window-reveal strips, noise) are dropped.

A curved facade has no peaks of its own, so it is cut into segments about
``min_facade_separation_deg`` wide.
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import gaussian_filter1d

from envelope.classes import FACADE_CLASSES, NUM_CLASSES
from envelope.mesh import triangle_areas_m2, triangle_normals
from neural3d.extraction.facade_planes import azimuth_offset, circular_mean_deg, wrap_deg
from neural3d.extraction.measure_config import MeasureConfig


def class_area_m2(
    vertices_m: np.ndarray, faces: np.ndarray, vertex_labels: np.ndarray
) -> np.ndarray:
    """Area of every triangle shared among classes by its vertices' classes.

    Returns
    -------
    (F, NUM_CLASSES) float64 m²; row f sums to the area of triangle f.
    """
    vertices_m, faces, labels = check_mesh_inputs(vertices_m, faces, vertex_labels)
    corner_labels = labels[faces]  # (F, 3)
    counts = np.stack([(corner_labels == c).sum(axis=1) for c in range(NUM_CLASSES)], axis=1)
    return triangle_areas_m2(vertices_m[faces])[:, None] * counts / 3.0


def group_facade_faces(
    vertices_m: np.ndarray,
    faces: np.ndarray,
    vertex_labels: np.ndarray,
    *,
    config: MeasureConfig = MeasureConfig(),
) -> np.ndarray:
    """Facade group of every triangle (see the module docstring).

    Returns
    -------
    (F,) int64 group index from 0, in increasing azimuth then offset; -1 for
    triangles in no facade.
    """
    vertices_m, faces, labels = check_mesh_inputs(vertices_m, faces, vertex_labels)
    facade_area = class_area_m2(vertices_m, faces, labels)[:, list(FACADE_CLASSES)].sum(axis=1)
    return group_faces(vertices_m, faces, facade_area, config)


def group_faces(vertices_m: np.ndarray, faces: np.ndarray, facade_area_m2: np.ndarray,
                config: MeasureConfig) -> np.ndarray:
    """:func:`group_facade_faces` on checked inputs and (F,) facade-class areas in m²."""
    normal = triangle_normals(vertices_m[faces])
    horizontal = np.linalg.norm(normal[:, :2], axis=1)
    candidate = ((facade_area_m2 > 0)
                 & (horizontal >= np.cos(np.radians(config.facade_max_tilt_deg))))
    group = np.full(len(faces), -1, dtype=np.int64)
    idx = np.flatnonzero(candidate)
    if len(idx) == 0:
        return group
    azimuth = np.degrees(np.arctan2(normal[idx, 1], normal[idx, 0])) % 360.0
    peaks = _azimuth_peaks_deg(azimuth, facade_area_m2[idx], config)
    nearest = np.argmin(np.abs(wrap_deg(azimuth[:, None] - peaks[None, :])), axis=1)
    centroid_xy = vertices_m[faces].mean(axis=1)[:, :2]
    groups: list[np.ndarray] = []
    for k in range(len(peaks)):
        members = idx[nearest == k]
        mean_az = circular_mean_deg(azimuth[nearest == k], facade_area_m2[members])
        u = np.array([np.cos(np.radians(mean_az)), np.sin(np.radians(mean_az))])
        tangent = np.array([-u[1], u[0]])
        for plane in split_at_gaps(members, centroid_xy[members] @ u, config.plane_gap_m):
            groups.extend(split_at_gaps(plane, centroid_xy[plane] @ tangent,
                                        config.plane_extent_gap_m))
    min_area = config.min_group_area_m2(sum(float(facade_area_m2[g].sum()) for g in groups))
    kept = [g for g in groups if facade_area_m2[g].sum() >= min_area]
    for i, members in enumerate(sorted(kept, key=lambda g: facade_key(
            normal[g], centroid_xy[g], facade_area_m2[g]))):
        group[members] = i
    return group


def split_at_gaps(members: np.ndarray, coordinate_m: np.ndarray, gap_m: float
                  ) -> list[np.ndarray]:
    """(N,) ``members`` cut into runs, in increasing (N,) ``coordinate_m``, wherever two
    neighbouring coordinates lie more than ``gap_m`` apart."""
    order = np.argsort(coordinate_m, kind="stable")
    cuts = np.flatnonzero(np.diff(coordinate_m[order]) > gap_m) + 1
    return [members[order][piece] for piece in np.split(np.arange(len(order)), cuts)]


def facade_key(normal: np.ndarray, centroid_xy: np.ndarray, weight: np.ndarray
               ) -> tuple[float, float, float]:
    """The order of facades: weighted mean azimuth (deg), offset (m) along it, then the
    weighted mean position (m) along the plane's tangent (pieces of one plane)."""
    azimuth, offset = azimuth_offset(normal, centroid_xy, weight)
    a = np.radians(azimuth)
    return azimuth, offset, float(np.average(centroid_xy @ np.array([-np.sin(a), np.cos(a)]),
                                             weights=weight))


def _azimuth_peaks_deg(azimuth_deg: np.ndarray, weight: np.ndarray,
                       config: MeasureConfig) -> np.ndarray:
    n_bins = max(1, int(round(360.0 / config.azimuth_bin_deg)))
    bin_deg = 360.0 / n_bins
    hist = np.bincount((azimuth_deg / bin_deg).astype(int) % n_bins, weights=weight,
                       minlength=n_bins)
    if config.azimuth_smoothing_deg > 0:
        hist = gaussian_filter1d(hist, config.azimuth_smoothing_deg / bin_deg, mode="wrap")
    centres = (np.arange(n_bins) + 0.5) * bin_deg
    floor = 1e-9 * hist.max()
    peaks = []
    while hist.max() > floor:
        i = int(np.argmax(hist))
        peaks.append(centres[i])
        hist[np.abs(wrap_deg(centres - centres[i])) < config.min_facade_separation_deg] = 0.0
    return np.array(peaks)


def check_mesh_inputs(vertices_m, faces, vertex_labels
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(V, 3) float64 vertices, (F, 3) int64 faces and (V,) int64 class ids, checked.

    Raises
    ------
    ValueError
        On malformed arrays or class ids outside the known classes.
    """
    v = np.asarray(vertices_m, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    lab = np.asarray(vertex_labels)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"vertices_m must have shape (V, 3), got {v.shape}")
    if f.ndim != 2 or f.shape[1] != 3:
        raise ValueError(f"faces must have shape (F, 3), got {f.shape}")
    if len(f) and (f.min() < 0 or f.max() >= len(v)):
        raise ValueError("faces index vertices that do not exist")
    if lab.shape != (len(v),):
        raise ValueError(f"vertex_labels must have shape ({len(v)},), got {lab.shape}")
    if len(lab) and (lab.min() < 0 or lab.max() >= NUM_CLASSES):
        raise ValueError(f"vertex_labels hold class ids outside 0..{NUM_CLASSES - 1}")
    return v, f, lab.astype(np.int64)
