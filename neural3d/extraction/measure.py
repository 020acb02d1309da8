"""Window, wall and door areas, WWR and per-facade figures from a mesh with per-vertex classes.

Areas follow the paper: each triangle's area is shared among classes by the
fraction of its three vertices in each class (a triangle with two window
vertices and one wall vertex gives 2/3 of its area to window, 1/3 to wall).
Gross facade = wall + window + door; roof, other and background never count.
Given the vertices' class probabilities, the facade part of each triangle is
then split among wall, window and door by them instead
(:mod:`neural3d.extraction.facade_split`).

Only faces seen from outside count (``MeasureConfig.visibility_rays_per_sample``
> 0, :func:`dataset.rendering.visibility.seen_from_outside`: some ray from the
face leaves the mesh): a surface a trained field closes inside the building (a
blob behind the windows, the sides of a tunnel at the door) has no area.

Facades are found without ground truth, from the horizontal direction of the
facade triangles' normals:

1. facade triangles (some wall/window/door vertex) whose normal is within
   ``facade_max_tilt_deg`` of horizontal take part;
2. their azimuths go into an area-weighted circular histogram, smoothed with a
   Gaussian; peaks are taken greedily, highest first, each suppressing its
   neighbours within ``min_facade_separation_deg``;
3. every triangle joins its nearest peak; within a peak, triangles are split
   into parallel planes where their offsets along the peak normal leave a gap
   larger than ``plane_gap_m`` (the two parallel walls of an L-shape);
4. groups smaller than ``min_facade_area_m2`` or ``min_facade_area_fraction`` of
   the grouped area (window-reveal strips, noise) are dropped.

How areas are counted (``MeasureConfig.count``):

- ``"projected"`` (default): the groups only propose facade planes (their mean
  normal and offset). Planes are then taken greedily, the one with the most
  projected facade area first; a plane claims every unclaimed facade triangle
  within ``plane_slab_m`` of it that faces it within ``plane_max_angle_deg``,
  and a triangle counts with its area projected onto the plane (area x n.N).
  So the sloped sides of a rounded window recess, a wavy wall or a reveal
  count once, as their shadow on the facade plane, as the truth's openings do;
  a surface that faces up or down (the underside a neural field may close the
  building with at the ground, the floor of a recess) counts for nothing.
  A triangle that faces two planes at least ``plane_max_angle_deg`` apart (the
  cut corner between two walls) counts on both; on a plane's own triangles the
  shadow is divided by the cosine of their ``curve_strip_m`` wide strip, so a
  curved wall keeps its true area. Facade triangles near no plane count with
  their full area if they are within ``facade_max_tilt_deg`` of vertical (a
  wall curving away from every plane), else not at all.
  With ``occlusion_cell_m`` > 0 (``"projected"`` only; default 0.1 m), each plane is
  also probed from in front on a grid (:mod:`neural3d.extraction.occluded_facade`):
  facade triangles a ray from in front meets first count even where the
  visibility test below dropped them (the back of a balcony), and facade hidden
  behind a balcony or another non-facade solid is filled from the nearest seen
  cells above and below it in its column; and where two walls meet in a concave
  corner that the field filled (``corner_max_gap_m`` > 0), each wall's rows are
  continued to the corner line (:mod:`neural3d.extraction.concave_corners`).
- ``"all"`` sums the classes over every triangle (the paper);
- ``"grouped"`` only over triangles in a kept group.

A curved facade has no peaks of its own, so it is cut into segments about
``min_facade_separation_deg`` wide; the whole-building figures do not depend on
the grouping.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.ndimage import gaussian_filter1d

from dataset.core.classes import FACADE_CLASSES, NUM_CLASSES, SemanticClass
from dataset.core.mesh import triangle_areas_m2, triangle_normals
from dataset.core.wwr import gross_facade_area_m2, wwr_from_areas
from dataset.rendering.raycast import Raycaster
from dataset.rendering.visibility import seen_from_outside
from neural3d.extraction.concave_corners import concave_corner_fill
from neural3d.extraction.facade_planes import (
    FacadePlanes,
    azimuth_offset,
    circular_mean_deg,
    project_onto_facade_planes,
    wrap_deg,
)
from neural3d.extraction.facade_split import split_facade_area_by_probability
from neural3d.extraction.measure_config import MeasureConfig
from neural3d.extraction.occluded_facade import (
    PlaneProbe,
    front_seen_faces,
    occluded_facade_area_m2,
    occluded_facade_labels,
    probe_planes,
)


@dataclass(frozen=True)
class MeshFacade:
    """One facade group of the mesh.

    ``normal`` is the horizontal outward unit vector (world, z = 0) at
    ``azimuth_deg`` (counter-clockwise from +x); ``offset_m`` the plane's
    distance from the origin along it; ``height_m`` the z extent of its
    triangles and ``width_m`` the gross area over the height: exact for a
    rectangular facade, the arc length for a curved one, and, unlike an extent
    along the wall, blind to stray triangles whose normals join a neighbour.
    ``centre_m`` is the centroid (world m) of its triangles weighted by their
    facade-class area: where the facade is, for matching it to another's.
    """

    index: int
    normal: tuple[float, float, float]
    azimuth_deg: float
    offset_m: float
    window_area_m2: float
    wall_area_m2: float
    door_area_m2: float
    facade_area_m2: float
    wwr: float | None
    width_m: float
    height_m: float
    face_count: int
    centre_m: tuple[float, float, float]


@dataclass(frozen=True)
class MeshMeasurement:
    """Whole-building figures (m²) of a semantic mesh; ``wwr`` is None without facade area."""

    window_area_m2: float
    wall_area_m2: float
    door_area_m2: float
    facade_area_m2: float
    wwr: float | None
    facades: tuple[MeshFacade, ...]
    ungrouped_facade_area_m2: float


def class_area_m2(
    vertices_m: np.ndarray, faces: np.ndarray, vertex_labels: np.ndarray
) -> np.ndarray:
    """Area of every triangle shared among classes by its vertices' classes.

    Returns
    -------
    (F, NUM_CLASSES) float64 m²; row f sums to the area of triangle f.
    """
    vertices_m, faces, labels = _check_inputs(vertices_m, faces, vertex_labels)
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
    vertices_m, faces, labels = _check_inputs(vertices_m, faces, vertex_labels)
    facade_area = class_area_m2(vertices_m, faces, labels)[:, list(FACADE_CLASSES)].sum(axis=1)
    return _group_faces(vertices_m, faces, facade_area, config)


def _group_faces(vertices_m: np.ndarray, faces: np.ndarray, facade_area: np.ndarray,
                 config: MeasureConfig) -> np.ndarray:
    """:func:`group_facade_faces` on checked inputs and (F,) facade-class areas in m²."""
    normal = triangle_normals(vertices_m[faces])
    horizontal = np.linalg.norm(normal[:, :2], axis=1)
    candidate = (facade_area > 0) & (horizontal >= np.cos(np.radians(config.facade_max_tilt_deg)))
    group = np.full(len(faces), -1, dtype=np.int64)
    idx = np.flatnonzero(candidate)
    if len(idx) == 0:
        return group
    azimuth = np.degrees(np.arctan2(normal[idx, 1], normal[idx, 0])) % 360.0
    peaks = _azimuth_peaks_deg(azimuth, facade_area[idx], config)
    nearest = np.argmin(np.abs(wrap_deg(azimuth[:, None] - peaks[None, :])), axis=1)
    centroid_xy = vertices_m[faces].mean(axis=1)[:, :2]
    groups: list[np.ndarray] = []
    for k in range(len(peaks)):
        members = idx[nearest == k]
        mean_az = circular_mean_deg(azimuth[nearest == k], facade_area[members])
        u = np.array([np.cos(np.radians(mean_az)), np.sin(np.radians(mean_az))])
        offsets = centroid_xy[members] @ u
        order = np.argsort(offsets)
        cuts = np.flatnonzero(np.diff(offsets[order]) > config.plane_gap_m) + 1
        groups.extend(members[order][piece] for piece in np.split(np.arange(len(order)), cuts))
    min_area = config.min_group_area_m2(sum(float(facade_area[g].sum()) for g in groups))
    kept = [g for g in groups if facade_area[g].sum() >= min_area]
    for i, members in enumerate(sorted(kept, key=lambda g: azimuth_offset(
            normal[g], centroid_xy[g], facade_area[g]))):
        group[members] = i
    return group


def measure_semantic_mesh(
    vertices_m: np.ndarray,
    faces: np.ndarray,
    vertex_labels: np.ndarray,
    *,
    config: MeasureConfig = MeasureConfig(),
    vertex_probabilities: np.ndarray | None = None,
) -> MeshMeasurement:
    """Window, wall, door and gross facade areas, WWR and per-facade figures of a semantic mesh.

    Parameters
    ----------
    vertices_m : (V, 3) float, world metres (z up)
    faces : (F, 3) int, outward-oriented
    vertex_labels : (V,) int class ids (:mod:`dataset.core.classes`)
    vertex_probabilities : optional (V, NUM_CLASSES) class probabilities; when given, each
        triangle's facade area (from the labels) is split among wall, window and door by
        them (:mod:`neural3d.extraction.facade_split`)

    Raises
    ------
    ValueError
        On malformed arrays or class ids outside the known classes.
    """
    vertices_m, faces, labels = _check_inputs(vertices_m, faces, vertex_labels)
    shares = class_area_m2(vertices_m, faces, labels)
    if vertex_probabilities is not None:
        shares = split_facade_area_by_probability(shares, faces, vertex_probabilities)
    areas = shares.copy()  # the hidden faces' go to 0 below
    facade_classes = list(FACADE_CLASSES)
    facade_area = areas[:, facade_classes].sum(axis=1)
    occlusion = config.count == "projected" and config.occlusion_cell_m > 0
    caster = (Raycaster.from_triangles(vertices_m, faces) if len(faces) and (
        config.visibility_rays_per_sample > 0 or occlusion) else None)
    if config.visibility_rays_per_sample > 0 and caster is not None:
        facade = facade_area > 0
        hidden = facade & ~_seen_from_outside(caster, facade, config)
        areas[hidden] = 0.0
        facade_area[hidden] = 0.0
    group = _group_faces(vertices_m, faces, facade_area, config)
    hidden_by_class = np.zeros(NUM_CLASSES)
    if config.count == "projected":
        planes = project_onto_facade_planes(vertices_m, faces, facade_area, group, config=config)
        behind = np.zeros((len(planes.azimuth_deg), NUM_CLASSES))
        if occlusion and caster is not None:
            probes = _probe(caster, shares, planes, config)
            back = (facade_area == 0) & front_seen_faces(probes, len(faces))
            if back.any():  # seen from in front, dropped by the hemisphere test: they count
                areas[back] = shares[back]
                facade_area = areas[:, facade_classes].sum(axis=1)
                group = _group_faces(vertices_m, faces, facade_area, config)
                planes = project_onto_facade_planes(vertices_m, faces, facade_area, group,
                                                    config=config)
                probes = _probe(caster, shares, planes, config)
            labels = occluded_facade_labels(caster, shares, planes, probes,
                                            slab_m=config.plane_slab_m,
                                            reach_m=config.occluder_reach_m)
            behind = occluded_facade_area_m2(probes, labels, cell_m=config.occlusion_cell_m)
            corners = concave_corner_fill(caster, planes, probes, labels,
                                          cell_m=config.occlusion_cell_m,
                                          reach_m=config.occluder_reach_m,
                                          max_gap_m=config.corner_max_gap_m,
                                          strip_m=config.curve_strip_m)
            behind, planes = behind + corners.area_m2, corners.planes
        hidden_by_class = behind.sum(axis=0)
        counted = areas * (planes.weight.sum(axis=1) + planes.residual)[:, None]
        facades = tuple(
            _facade_figures(k, vertices_m, faces, areas * planes.weight[:, k, None],
                            planes.weight[:, k] > 0, plane=(az, off), behind=behind[k])
            for k, (az, off) in enumerate(zip(planes.azimuth_deg, planes.offset_m)))
        ungrouped = float((areas[:, facade_classes].sum(axis=1) * planes.residual).sum())
    else:
        counted = areas if config.count == "all" else areas[group >= 0]
        facades = tuple(_facade_figures(i, vertices_m, faces, areas, group == i)
                        for i in range(int(group.max()) + 1))
        ungrouped = float(areas[group < 0][:, facade_classes].sum())
    window, wall, door = (float(counted[:, c].sum() + hidden_by_class[c]) for c in
                          (SemanticClass.WINDOW, SemanticClass.WALL, SemanticClass.DOOR))
    return MeshMeasurement(
        window_area_m2=window,
        wall_area_m2=wall,
        door_area_m2=door,
        facade_area_m2=gross_facade_area_m2(wall, window, door),
        wwr=wwr_from_areas(window, wall, door),
        facades=facades,
        ungrouped_facade_area_m2=ungrouped,
    )


def _probe(caster: Raycaster, shares: np.ndarray, planes: FacadePlanes,
           config: MeasureConfig) -> list[PlaneProbe | None]:
    return probe_planes(caster, shares, planes, cell_m=config.occlusion_cell_m,
                        slab_m=config.plane_slab_m, max_angle_deg=config.plane_max_angle_deg)


def _seen_from_outside(caster: Raycaster, which: np.ndarray,
                       config: MeasureConfig) -> np.ndarray:
    """(F,) bool: faces in ``which`` that some ray from them leaves without a hit."""
    return seen_from_outside(caster, which,
                             rays_per_sample=config.visibility_rays_per_sample,
                             offset_m=config.ray_offset_m,
                             min_escape_fraction=config.min_escape_fraction, ground=True)


def _facade_figures(
    index: int, vertices_m: np.ndarray, faces: np.ndarray, areas: np.ndarray, mask: np.ndarray,
    plane: tuple[float, float] | None = None, behind: np.ndarray | None = None,
) -> MeshFacade:
    """Figures of the triangles in ``mask``; ``plane`` (azimuth deg, offset m) if known;
    ``behind`` (NUM_CLASSES,) m² hidden behind occluders, added to the classes' areas."""
    tri = vertices_m[faces[mask]]
    a = areas[mask]
    extra = np.zeros(NUM_CLASSES) if behind is None else behind
    window, wall, door = (float(a[:, c].sum() + extra[c]) for c in
                          (SemanticClass.WINDOW, SemanticClass.WALL, SemanticClass.DOOR))
    weight = a[:, list(FACADE_CLASSES)].sum(axis=1)
    azimuth, offset = plane if plane is not None else azimuth_offset(
        triangle_normals(tri), tri.mean(axis=1)[:, :2], weight)
    azimuth, offset = float(azimuth), float(offset)
    u = np.array([np.cos(np.radians(azimuth)), np.sin(np.radians(azimuth))])
    height = float(tri[..., 2].max() - tri[..., 2].min())
    gross = gross_facade_area_m2(wall, window, door)
    return MeshFacade(
        index=index,
        normal=(round(float(u[0]), 12) + 0.0, round(float(u[1]), 12) + 0.0, 0.0),
        azimuth_deg=float(azimuth),
        offset_m=offset,
        window_area_m2=window,
        wall_area_m2=wall,
        door_area_m2=door,
        facade_area_m2=gross,
        wwr=wwr_from_areas(window, wall, door),
        width_m=gross / height if height > 0 else 0.0,
        height_m=height,
        face_count=int(mask.sum()),
        centre_m=tuple(float(c) for c in np.average(tri.mean(axis=1), axis=0, weights=weight)),
    )


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


def _check_inputs(vertices_m, faces, vertex_labels) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
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
