"""The semantic mesh file: a binary PLY with per-vertex RGB and class id (``label``).

Methods that keep a mesh (neural3d's ``extract/mesh.ply``) write it with
:func:`write_semantic_ply`; the figures and the HTML report read it with
:func:`read_semantic_ply` (any PLY with a per-vertex ``label`` reads).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from envelope.atomic import write_bytes_atomic
from envelope.mesh import read_ply_with_properties

_PLY_HEADER = (
    "ply\n"
    "format binary_little_endian 1.0\n"
    "comment envelope-bench semantic mesh: label = class id (0 background, 1 wall, 2 window, "
    "3 roof, 4 door, 5 other)\n"
    "element vertex {nv}\n"
    "property float x\nproperty float y\nproperty float z\n"
    "property uchar red\nproperty uchar green\nproperty uchar blue\n"
    "property uchar label\n"
    "element face {nf}\n"
    "property list uchar int vertex_indices\n"
    "end_header\n"
)
_VERTEX_DTYPE = np.dtype([("p", "<f4", (3,)), ("rgb", "u1", (3,)), ("label", "u1")])
_FACE_DTYPE = np.dtype([("n", "u1"), ("v", "<i4", (3,))])


def write_semantic_ply(
    path: str | Path,
    vertices_m: np.ndarray,
    faces: np.ndarray,
    vertex_labels: np.ndarray,
    vertex_rgb: np.ndarray,
) -> None:
    """Write a binary PLY with per-vertex RGB and ``label`` (atomically).

    Vertices are stored as float32 (sub-millimetre within 1 km of the origin),
    which every viewer reads; MeshLab and Blender show the RGB.
    """
    vertices_m, faces = check_mesh_arrays(vertices_m, faces)
    labels = np.asarray(vertex_labels)
    rgb = np.asarray(vertex_rgb)
    if labels.shape != (len(vertices_m),) or rgb.shape != (len(vertices_m), 3):
        raise ValueError(f"vertex_labels must be ({len(vertices_m)},) and vertex_rgb "
                         f"({len(vertices_m)}, 3), got {labels.shape} and {rgb.shape}")
    if rgb.dtype != np.uint8:
        raise ValueError(f"vertex_rgb must be uint8 (0-255), got {rgb.dtype}")
    vertex = np.zeros(len(vertices_m), dtype=_VERTEX_DTYPE)
    vertex["p"] = vertices_m
    vertex["rgb"] = rgb
    vertex["label"] = labels
    face = np.zeros(len(faces), dtype=_FACE_DTYPE)
    face["n"] = 3
    face["v"] = faces
    header = _PLY_HEADER.format(nv=len(vertex), nf=len(face)).encode("ascii")
    write_bytes_atomic(path, header + vertex.tobytes() + face.tobytes())


def read_semantic_ply(path: str | Path) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Read a PLY with a per-vertex ``label`` (any PLY trimesh reads).

    Returns
    -------
    vertices_m : (V, 3) float64, faces : (F, 3) int64, labels : (V,) uint8, rgb : (V, 3) uint8
    (grey 128 where the file has no colour).

    Raises
    ------
    ValueError
        If the file is missing, unreadable or has no vertex ``label``.
    """
    tm, raw = read_ply_with_properties(path, "vertex")
    names = raw.dtype.names if raw is not None else None
    if "label" not in (names or ()):
        raise ValueError(f"{path} has no per-vertex 'label' property; write it with "
                         "envelope.semantic_ply.write_semantic_ply")
    labels = np.asarray(raw["label"]).reshape(-1).astype(np.uint8)
    if all(c in names for c in ("red", "green", "blue")):
        rgb = np.stack([np.asarray(raw[c]).reshape(-1) for c in ("red", "green", "blue")], 1)
    else:
        rgb = np.full((len(labels), 3), 128)
    return (np.asarray(tm.vertices, dtype=np.float64), np.asarray(tm.faces, dtype=np.int64),
            labels, rgb.astype(np.uint8))




def check_points_m(points_m: np.ndarray) -> np.ndarray:
    p = np.asarray(points_m, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"points must have shape (N, 3), got {p.shape}")
    return p


def check_mesh_arrays(vertices_m: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    v = check_points_m(vertices_m)
    f = np.asarray(faces, dtype=np.int64)
    if f.ndim != 2 or f.shape[1] != 3:
        raise ValueError(f"faces must have shape (F, 3), got {f.shape}")
    if len(f) and (f.min() < 0 or f.max() >= len(v)):
        raise ValueError("faces index vertices that do not exist")
    return v, f
