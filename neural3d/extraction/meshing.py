"""Marching-cubes mesh of a signed distance function, per-vertex semantics and colour.

The mesh is written with :func:`envelope.semantic_ply.write_semantic_ply`.

The core works on plain NumPy callables so it does not depend on torch:

- ``SdfFn``: (N, 3) world metres -> (N,) signed distance in m, positive outside;
- ``LabelFn``: (N, 3) world metres -> (N,) int class ids (:mod:`envelope.classes`);
- ``ColorFn``: (N, 3) world metres, (N, 3) unit view directions -> (N, 3) float in [0, 1].

The grid is evaluated in groups of x slabs of about ``chunk_points`` points into
one float32 volume (512³ = 0.5 GB), so memory is bounded by the volume plus one
group. The callables take whole arrays: a trained field splits its own calls
(:mod:`neural3d.field.chunks`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from tqdm import tqdm

from envelope.classes import NUM_CLASSES
from envelope.mesh import triangle_areas_m2
from envelope.semantic_ply import check_mesh_arrays, check_points_m
from neural3d.field.chunks import DEFAULT_CHUNK_POINTS

SdfFn = Callable[[np.ndarray], np.ndarray]
LabelFn = Callable[[np.ndarray], np.ndarray]
ColorFn = Callable[[np.ndarray, np.ndarray], np.ndarray]

MAX_GRID_SAMPLES = 1025  # per axis; 1025³ float32 is 4.3 GB, the most we allow in memory


@dataclass(frozen=True)
class SemanticMesh:
    """A mesh with per-vertex class and colour, world metres.

    Attributes
    ----------
    vertices_m : (V, 3) float64
    faces : (F, 3) int64, counter-clockwise seen from outside
    vertex_labels : (V,) uint8 class ids
    vertex_rgb : (V, 3) uint8
    vertex_probabilities : (V, NUM_CLASSES) float32 class probabilities in
        :mod:`envelope.classes` id order (``vertex_labels`` is their argmax)
    """

    vertices_m: np.ndarray
    faces: np.ndarray
    vertex_labels: np.ndarray
    vertex_rgb: np.ndarray
    vertex_probabilities: np.ndarray


def grid_axes_m(
    box_min_m: np.ndarray,
    box_max_m: np.ndarray,
    *,
    resolution: int | None = None,
    voxel_size_m: float | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Sample positions along x, y and z for a grid over the box.

    ``resolution`` is the number of samples along the box's longest side;
    ``voxel_size_m`` the spacing. Give exactly one. Every axis gets the same
    spacing (cubic voxels), and its samples are centred in the box.

    Returns
    -------
    xs, ys, zs : (nx,), (ny,), (nz,) float64 positions in m.
    """
    lo, hi = check_box(box_min_m, box_max_m)
    if (resolution is None) == (voxel_size_m is None):
        raise ValueError("give exactly one of resolution (samples along the longest side) "
                         "or voxel_size_m")
    extent = hi - lo
    if resolution is not None:
        if int(resolution) != resolution or resolution < 2:
            raise ValueError(f"resolution must be an integer >= 2, got {resolution}")
        voxel = float(extent.max()) / (int(resolution) - 1)
    else:
        voxel = float(voxel_size_m)
        if not np.isfinite(voxel) or voxel <= 0:
            raise ValueError(f"voxel_size_m must be > 0, got {voxel_size_m}")
    counts = np.floor(extent / voxel + 1e-9).astype(int) + 1
    counts = np.maximum(counts, 2)
    if counts.max() > MAX_GRID_SAMPLES:
        raise ValueError(
            f"grid of {tuple(counts)} samples is too large (at most {MAX_GRID_SAMPLES} per axis); "
            "lower the resolution or raise voxel_size_m"
        )
    centre = 0.5 * (lo + hi)
    return tuple(centre[i] + voxel * (np.arange(counts[i]) - 0.5 * (counts[i] - 1))
                 for i in range(3))


def sample_sdf_grid(
    sdf_fn: SdfFn,
    xs: np.ndarray,
    ys: np.ndarray,
    zs: np.ndarray,
    *,
    chunk_points: int = DEFAULT_CHUNK_POINTS,
    progress: bool = False,
) -> np.ndarray:
    """Evaluate ``sdf_fn`` on the grid ``xs × ys × zs``, x slabs grouped into calls of at
    most ``chunk_points`` points (one slab when a slab holds more).

    Returns
    -------
    (nx, ny, nz) float32 signed distances in m, indexed [ix, iy, iz].
    """
    if chunk_points < 1:
        raise ValueError(f"chunk_points must be >= 1, got {chunk_points}")
    nx, ny, nz = len(xs), len(ys), len(zs)
    volume = np.empty((nx, ny, nz), dtype=np.float32)
    yy, zz = np.meshgrid(ys, zs, indexing="ij")
    plane_yz = np.stack([yy.ravel(), zz.ravel()], axis=1)
    slabs_per_chunk = max(1, chunk_points // (ny * nz))
    starts = range(0, nx, slabs_per_chunk)
    for start in tqdm(starts, desc="sdf grid", unit="slab", disable=not progress):
        stop = min(start + slabs_per_chunk, nx)
        values = evaluate_points(sdf_fn, _slab_points(xs[start:stop], plane_yz))
        volume[start:stop] = values.reshape(stop - start, ny, nz)
    if not np.isfinite(volume).all():
        raise ValueError("the SDF returned NaN or inf on the grid; check the field")
    return volume


def extract_mesh(
    sdf_fn: SdfFn,
    box_min_m: np.ndarray,
    box_max_m: np.ndarray,
    *,
    resolution: int | None = None,
    voxel_size_m: float | None = None,
    chunk_points: int = DEFAULT_CHUNK_POINTS,
    min_component_area_fraction: float = 0.0,
    progress: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    """Zero level set of an SDF as a triangle mesh (marching cubes).

    Parameters
    ----------
    sdf_fn : callable (N, 3) -> (N,)
        Signed distance in m, positive outside, world frame.
    box_min_m, box_max_m : (3,) float
        Corners of the box to mesh, world metres.
    resolution, voxel_size_m
        Samples along the longest box side, or the voxel size in m (exactly one).
    chunk_points : int
        Points per call of ``sdf_fn``: whole x slabs up to this many (one slab if more).
    min_component_area_fraction : float in [0, 1)
        Connected pieces with less than this fraction of the total area are removed
        (floaters); 0 keeps everything.

    Returns
    -------
    vertices_m : (V, 3) float64, world metres.
    faces : (F, 3) int64, counter-clockwise seen from outside (normals point out).

    Raises
    ------
    ValueError
        If the SDF has no zero crossing in the box, or on bad arguments.
    """
    if not 0.0 <= min_component_area_fraction < 1.0:
        raise ValueError(
            f"min_component_area_fraction must be in [0, 1), got {min_component_area_fraction}"
        )
    xs, ys, zs = grid_axes_m(box_min_m, box_max_m, resolution=resolution,
                             voxel_size_m=voxel_size_m)
    volume = sample_sdf_grid(sdf_fn, xs, ys, zs, chunk_points=chunk_points, progress=progress)
    lo, hi = float(volume.min()), float(volume.max())
    if not lo < 0.0 < hi:
        raise ValueError(
            f"the SDF has no zero crossing in the box (values from {lo:.4g} to {hi:.4g} m); "
            "the surface lies outside the box or the field is empty: check the box and the field"
        )
    vertices_m, faces = _marching_cubes(volume, xs, ys, zs)
    del volume
    if min_component_area_fraction > 0:
        vertices_m, faces = remove_small_components(vertices_m, faces, min_component_area_fraction)
    return vertices_m, faces


def remove_small_components(
    vertices_m: np.ndarray, faces: np.ndarray, min_area_fraction: float
) -> tuple[np.ndarray, np.ndarray]:
    """Drop connected pieces (sharing vertices) whose area is below a fraction of the total.

    Returns the kept mesh with unused vertices removed and faces re-indexed.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    vertices_m, faces = check_mesh_arrays(vertices_m, faces)
    if len(faces) == 0:
        return vertices_m, faces
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]]])
    graph = coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])),
                       shape=(len(vertices_m),) * 2)
    _, vertex_component = connected_components(graph, directed=False)
    face_component = vertex_component[faces[:, 0]]
    area = np.bincount(face_component, weights=triangle_areas_m2(vertices_m[faces]))
    keep_face = area[face_component] >= min_area_fraction * area.sum()
    return compact_mesh(vertices_m, faces[keep_face])


def compact_mesh(vertices_m: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Remove vertices no face uses and re-index the faces; vertex order is kept."""
    used = np.zeros(len(vertices_m), dtype=bool)
    used[faces.ravel()] = True
    new_index = np.cumsum(used) - 1
    return vertices_m[used], new_index[faces]


def vertex_normals(vertices_m: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Area-weighted outward unit vertex normals, (V, 3) float64 (zero for isolated vertices)."""
    vertices_m, faces = check_mesh_arrays(vertices_m, faces)
    t = vertices_m[faces]
    face_n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])  # length = 2 × area: area weighting
    n = np.zeros_like(vertices_m)
    for k in range(3):
        np.add.at(n, faces[:, k], face_n)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return np.divide(n, length, out=np.zeros_like(n), where=length > 0)


def label_vertices(vertices_m: np.ndarray, label_fn: LabelFn) -> np.ndarray:
    """Class id of every vertex from ``label_fn`` (e.g. the argmax of a semantic head).

    Returns
    -------
    (V,) uint8 class ids.
    """
    vertices_m = check_points_m(vertices_m)
    labels = evaluate_points(label_fn, vertices_m)
    if len(labels) and (labels.min() < 0 or labels.max() >= NUM_CLASSES):
        raise ValueError(f"label_fn returned class ids outside 0..{NUM_CLASSES - 1}")
    return labels.astype(np.uint8)


def color_vertices(
    vertices_m: np.ndarray,
    faces: np.ndarray,
    color_fn: ColorFn,
) -> np.ndarray:
    """Colour of every vertex seen head-on: ``color_fn(points, view_dirs = -normal)``.

    Returns
    -------
    (V, 3) uint8 RGB.
    """
    normals = vertex_normals(vertices_m, faces)
    both = np.concatenate([vertices_m, -normals], axis=1)
    rgb = evaluate_points(lambda p: color_fn(p[:, :3], p[:, 3:]), both, out_shape=(3,))
    return np.round(np.clip(rgb, 0.0, 1.0) * 255.0).astype(np.uint8)


def evaluate_points(fn: Callable[[np.ndarray], np.ndarray], points: np.ndarray,
                    out_shape: tuple[int, ...] = ()) -> np.ndarray:
    """``fn`` on (N, D) points in one call: (N, *out_shape).

    Raises
    ------
    ValueError
        If ``fn`` returns another shape.
    """
    out = np.asarray(fn(points))
    if out.shape != (len(points), *out_shape):
        raise ValueError(f"the callable returned shape {out.shape} for {len(points)} points; "
                         f"expected {(len(points), *out_shape)}")
    return out


def _marching_cubes(
    volume: np.ndarray, xs: np.ndarray, ys: np.ndarray, zs: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    from skimage.measure import marching_cubes

    voxel = xs[1] - xs[0]
    # With "descent" skimage winds faces so that normals point towards larger values, i.e.
    # outwards for an SDF that is positive outside (test_meshing checks the signed volume).
    verts, faces, _, _ = marching_cubes(volume, level=0.0, spacing=(voxel,) * 3,
                                        gradient_direction="descent")
    origin = np.array([xs[0], ys[0], zs[0]])
    return verts.astype(np.float64) + origin, faces.astype(np.int64)


def _slab_points(xs: np.ndarray, plane_yz: np.ndarray) -> np.ndarray:
    pts = np.empty((len(xs), len(plane_yz), 3), dtype=np.float64)
    pts[:, :, 0] = xs[:, None]
    pts[:, :, 1:] = plane_yz[None]
    return pts.reshape(-1, 3)


def check_box(box_min_m, box_max_m) -> tuple[np.ndarray, np.ndarray]:
    """The box corners as (3,) float64 arrays; ValueError unless max > min on every axis."""
    lo = np.asarray(box_min_m, dtype=np.float64)
    hi = np.asarray(box_max_m, dtype=np.float64)
    if lo.shape != (3,) or hi.shape != (3,):
        raise ValueError(f"box corners must have shape (3,), got {lo.shape} and {hi.shape}")
    if not (np.isfinite(lo).all() and np.isfinite(hi).all() and (hi > lo).all()):
        raise ValueError(f"box_max_m {hi.tolist()} must exceed box_min_m {lo.tolist()} "
                         "on every axis")
    return lo, hi
