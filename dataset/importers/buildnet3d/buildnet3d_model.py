"""The BuildNet3D-dataset generator's segmented mesh ``model/{i}_segmented.ply`` -> our mesh.

The generator exports each building once more as an ASCII PLY whose vertex colours are
the segmentation colours (``composed_building.py:146-158``, ``export_colors="LINEAR"``)
and reads the classes back by the nearest palette colour (``segmented_3D_model.py:122-151``,
``post_process_segmentation.py:27-52``). Here every vertex takes the class of the nearest
palette colour, in sRGB or linearised (whichever encoding the file holds), a face the class
its vertices share (the majority where they differ), and wall and window faces parallel to
a wall of ``wwr_information`` and on its plane take that wall's facade id (window faces
may lie up to :data:`WINDOW_RECESS_M` behind or before it; reveals and frames at an angle
get none, as in :mod:`dataset.classes`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from envelope.classes import NO_FACADE, SemanticClass
from envelope.mesh import LabelledMesh
from envelope.scenes.labels import class_mapping

WALL_PLANE_M = 0.05
"""A wall face lies on a wall's plane within this (the generator's walls are exact)."""
WINDOW_RECESS_M = 0.5
"""A window face parallel to a wall lies within this of its plane (window modules are set
into the wall)."""
PARALLEL_COS = 0.99
"""A face belongs to a wall when its outward normal is within ~8 deg of the wall's (a window
module is a box through the wall: its back face, facing in, is not on the facade)."""


def read_segmented_model(path: str | Path, walls: list[dict[str, Any]]) -> LabelledMesh:
    """Our :class:`LabelledMesh` of a generator ``*_segmented.ply``.

    ``walls`` as :func:`dataset.buildnet3d.read_walls` gives them (index + 1 = facade id).

    Raises
    ------
    ValueError
        The file is missing, unreadable, has no faces or no vertex colours (Blender's
        exporter writes them beside UV coordinates ``s``, ``t``: both are read).
    """
    from trimesh.exchange.ply import load_ply

    path = Path(path)
    if not path.is_file():
        raise ValueError(f"segmented model {path} does not exist")
    try:
        with path.open("rb") as f:
            # fix_texture=False: Blender writes UVs (s, t) beside the colours; trimesh would
            # otherwise make a textured mesh and drop the vertex colours.
            ply = load_ply(f, fix_texture=False)
    except Exception as exc:  # trimesh raises many kinds on a bad file
        raise ValueError(f"{path} is not a readable PLY mesh: {exc}") from None
    faces = np.asarray(ply.get("faces", np.zeros((0, 3))), dtype=np.int64).reshape(-1, 3)
    vertices = np.asarray(ply.get("vertices", np.zeros((0, 3))), dtype=np.float64)
    colours = ply.get("vertex_colors")
    if len(faces) == 0:
        raise ValueError(f"{path} has no faces: not a segmented model")
    if colours is None or len(colours) != len(vertices):
        raise ValueError(f"{path} has no vertex colours (red, green, blue): not a segmented "
                         "model; export it with Blender's PLY exporter and colours on")
    vertex_class = classes_from_colours(np.asarray(colours)[:, :3])
    face_class = _majority(vertex_class[faces])
    return LabelledMesh(vertices, faces, face_class,
                        facade_ids_of_faces(vertices[faces], face_class, walls))


def classes_from_colours(rgb: np.ndarray) -> np.ndarray:
    """(N,) uint8 our class of (N, 3) uint8 colours: the nearest generator palette colour,
    sRGB or linearised."""
    gen = class_mapping("generator")
    palette = np.asarray(gen.colours, dtype=np.float64)
    linear = 255.0 * _srgb_to_linear(palette / 255.0)
    candidates = np.concatenate([palette, linear])
    ours = np.tile(np.asarray(gen.to_ours, dtype=np.uint8), 2)
    d = ((np.asarray(rgb, dtype=np.float64)[:, None, :] - candidates[None]) ** 2).sum(-1)
    return ours[np.argmin(d, axis=1)]


def facade_ids_of_faces(triangles_m: np.ndarray, face_class: np.ndarray,
                        walls: list[dict[str, Any]]) -> np.ndarray:
    """(F,) int32 facade id of (F, 3, 3) triangles: the wall whose plane a wall or window
    face lies on, facing the same way (0 = none)."""
    e1 = triangles_m[:, 1] - triangles_m[:, 0]
    e2 = triangles_m[:, 2] - triangles_m[:, 0]
    normal = np.cross(e1, e2)
    length = np.linalg.norm(normal, axis=1)
    normal = normal / np.where(length > 0, length, 1.0)[:, None]
    centre = triangles_m.mean(axis=1)
    tolerance = np.where(face_class == SemanticClass.WINDOW, WINDOW_RECESS_M, WALL_PLANE_M)
    candidate = np.isin(face_class, [SemanticClass.WALL, SemanticClass.WINDOW]) & (length > 0)
    out = np.full(len(triangles_m), NO_FACADE, dtype=np.int32)
    best = np.full(len(triangles_m), np.inf)
    for w, wall in enumerate(walls):
        dist = np.abs((centre - wall["center"]) @ wall["normal"])
        lo = wall["domain"][:, 0] - tolerance[:, None]
        hi = wall["domain"][:, 1] + tolerance[:, None]
        ok = (candidate & (normal @ wall["normal"] >= PARALLEL_COS)
              & (dist <= tolerance) & np.all((centre >= lo) & (centre <= hi), axis=1)
              & (dist < best))
        out[ok], best[ok] = w + 1, dist[ok]
    return out


def _majority(vertex_classes: np.ndarray) -> np.ndarray:
    """(F,) the class two or three of a face's (F, 3) vertex classes share, else vertex 0's."""
    a, b, c = vertex_classes.T
    return np.where((b == c) & (a != b), b, a).astype(np.uint8)


def _srgb_to_linear(x: np.ndarray) -> np.ndarray:
    return np.where(x <= 0.04045, x / 12.92, ((x + 0.055) / 1.055) ** 2.4)
