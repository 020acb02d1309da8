"""Read a user's labelled triangle mesh from PLY, OBJ or glTF/GLB into a :class:`LabelledMesh`.

PLY carries the class id per face (``label`` property, :func:`envelope.mesh.read_labelled_ply`).
OBJ and GLB carry it in names: each face takes its class from the first of its OBJ group
(``g``), object (``o``) or material (``usemtl``) names -- for GLB its node, mesh or material
names -- that names a class (:func:`class_from_name`). Coincident vertices are merged, so a
mesh split into one part per class is closed again where its parts meet.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Literal

import numpy as np

from dataset.importers.mesh.mesh_validation import check_mesh_coordinates
from envelope.classes import CLASS_NAMES, NO_FACADE, SemanticClass
from envelope.mesh import MERGE_DECIMALS, LabelledMesh, read_labelled_ply

UpAxis = Literal["z", "y"]

CLASS_SYNONYMS: dict[str, SemanticClass] = {
    "walls": SemanticClass.WALL,
    "facade": SemanticClass.WALL,
    "windows": SemanticClass.WINDOW,
    "glass": SemanticClass.WINDOW,
    "glazing": SemanticClass.WINDOW,
    "doors": SemanticClass.DOOR,
    "roofs": SemanticClass.ROOF,
}
"""Names accepted besides the class names themselves (lower case)."""

_NUMERIC_SUFFIX = re.compile(r"[._\- ]\d+$")  # Blender's "Wall.001", "window_3", "door-2"
_TOKEN_SPLIT = re.compile(r"[._\- ]+")


def class_from_name(name: str) -> SemanticClass | None:
    """The class a part's name stands for, or ``None`` if it names none.

    Case-insensitive. A trailing number (``Wall.001``, ``window_3``) is ignored, and a
    name whose first word (split at ``_ - . space``) is a class also counts
    (``Wall_North`` is a wall). :data:`CLASS_SYNONYMS` lists the accepted synonyms.
    """
    key = name.strip().lower()
    while _NUMERIC_SUFFIX.search(key):
        key = _NUMERIC_SUFFIX.sub("", key)
    for candidate in (key, _TOKEN_SPLIT.split(key)[0] if key else ""):
        if candidate in CLASS_NAMES:
            return SemanticClass(CLASS_NAMES.index(candidate))
        if candidate in CLASS_SYNONYMS:
            return CLASS_SYNONYMS[candidate]
    return None


def read_labelled_mesh_file(path: str | Path, *, up_axis: UpAxis = "z") -> LabelledMesh:
    """Read a labelled mesh file (``.ply``, ``.obj``, ``.glb``, ``.gltf``) in metres.

    Parameters
    ----------
    path
        The mesh file.
    up_axis
        The file's up axis; ``"y"`` rotates y-up files (glTF from Blender) to our z-up world.

    Returns
    -------
    LabelledMesh with merged vertices and every face's class; facade ids are all 0 (none).

    Raises
    ------
    ValueError
        Missing or unreadable file, unknown format, no labels, part names that name no class,
        NaN coordinates or an absurd size (:mod:`dataset.importers.mesh.mesh_validation`).
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"mesh file {path} does not exist")
    suffix = path.suffix.lower()
    if suffix == ".ply":
        ply = read_labelled_ply(path)
        vertices, faces, labels = ply.vertices_m, ply.faces, ply.face_label
    elif suffix == ".obj":
        vertices, faces, names = _read_obj(path)
        labels = _labels_from_names(path, names)
    elif suffix in (".glb", ".gltf"):
        vertices, faces, names = _read_gltf(path)
        labels = _labels_from_names(path, names)
    else:
        raise ValueError(
            f"{path}: unsupported mesh format {suffix!r}; use .ply (with a face 'label' "
            "property), .obj or .glb (with parts named after classes)"
        )
    if up_axis == "y":
        vertices = np.stack([vertices[:, 0], -vertices[:, 2], vertices[:, 1]], axis=1)
    elif up_axis != "z":
        raise ValueError(f"up_axis must be 'z' or 'y', got {up_axis!r}")
    check_mesh_coordinates(vertices, faces, path)
    vertices, faces = merge_vertices(vertices, faces)
    return LabelledMesh(vertices, faces, labels, np.full(len(faces), NO_FACADE))


def merge_vertices(vertices_m: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Merge vertices that coincide to :data:`MERGE_DECIMALS` decimals (face order kept).

    Parameters
    ----------
    vertices_m : (V, 3) float
    faces : (F, 3) int

    Returns
    -------
    vertices_m : (U, 3) float64 unique vertices, faces : (F, 3) int64 re-indexed.
    """
    v = np.asarray(vertices_m, dtype=np.float64)
    if len(v) == 0:
        return v.reshape(0, 3), np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    # +0.0 turns -0.0 into 0.0 so that both round to the same key.
    keys = np.round(v, MERGE_DECIMALS) + 0.0
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    return v[first], inverse.reshape(-1)[np.asarray(faces, dtype=np.int64)]


def _labels_from_names(path: Path, names: list[tuple[str, ...]]) -> np.ndarray:
    """(F,) uint8 class per face from each face's candidate names, first that names a class."""
    if not names:
        raise ValueError(f"{path} holds no faces; export the building's surfaces as triangles")
    cache: dict[tuple[str, ...], SemanticClass | None] = {}
    labels = np.zeros(len(names), dtype=np.uint8)
    unknown: set[tuple[str, ...]] = set()
    for i, candidates in enumerate(names):
        if candidates not in cache:
            cache[candidates] = next(
                (c for c in map(class_from_name, candidates) if c is not None), None
            )
        cls = cache[candidates]
        if cls is None:
            unknown.add(candidates)
        else:
            labels[i] = cls
    if unknown:
        shown = sorted("/".join(c) if c else "(unnamed)" for c in unknown)
        if all(not c for c in unknown):
            raise ValueError(
                f"{path} has no labels: its parts have no names. Name each object, group or "
                f"material after its class ({', '.join(CLASS_NAMES[1:])}) in the authoring tool"
            )
        raise ValueError(
            f"{path}: cannot tell the class of parts named {', '.join(shown[:10])}"
            f"{' ...' if len(shown) > 10 else ''}; name each object, group or material after "
            f"its class ({', '.join(CLASS_NAMES[1:])}; synonyms {', '.join(CLASS_SYNONYMS)})"
        )
    return labels


def _read_obj(path: Path) -> tuple[np.ndarray, np.ndarray, list[tuple[str, ...]]]:
    """Vertices, fan-triangulated faces and each face's (group, object, material) names.

    trimesh's OBJ loader drops group names and renames objects, so OBJ is parsed here.
    """
    vertices: list[list[float]] = []
    faces: list[tuple[int, int, int]] = []
    names: list[tuple[str, ...]] = []
    group = obj = material = ""
    try:
        lines = path.read_text(errors="replace").splitlines()
    except OSError as exc:
        raise ValueError(f"cannot read {path}: {exc}") from exc
    for number, line in enumerate(lines, start=1):
        parts = line.split("#", 1)[0].split()
        if not parts:
            continue
        tag, args = parts[0], parts[1:]
        try:
            if tag == "v":
                vertices.append([float(a) for a in args[:3]])
            elif tag == "f":
                idx = [_obj_index(a, len(vertices)) for a in args]
                part_names = tuple(n for n in (group, obj, material) if n)
                for k in range(1, len(idx) - 1):  # polygons become triangle fans
                    faces.append((idx[0], idx[k], idx[k + 1]))
                    names.append(part_names)
            elif tag == "g":
                group = " ".join(args)
            elif tag == "o":
                obj, group = " ".join(args), ""
            elif tag == "usemtl":
                material = " ".join(args)
        except (ValueError, IndexError) as exc:
            raise ValueError(f"{path}, line {number}: cannot parse {line.strip()!r}") from exc
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    if len(f) and (f.min() < 0 or f.max() >= len(v)):
        raise ValueError(f"{path}: a face refers to a vertex that does not exist")
    return v, f, names


def _obj_index(token: str, n_vertices: int) -> int:
    """0-based vertex index of an OBJ face token (``7``, ``7/1/2``, ``-1``)."""
    i = int(token.split("/")[0])
    return i - 1 if i > 0 else n_vertices + i


def _read_gltf(path: Path) -> tuple[np.ndarray, np.ndarray, list[tuple[str, ...]]]:
    """World vertices, faces and each face's (node, mesh, material) names of a glTF scene."""
    import trimesh

    try:
        scene = trimesh.load(path, force="scene", process=False)
    except Exception as exc:  # trimesh raises many types on bad files
        raise ValueError(f"cannot read {path} as glTF: {exc}") from exc
    vertices, faces, names = [], [], []
    offset = 0
    for node in scene.graph.nodes_geometry:
        transform, geom_name = scene.graph[node]
        geom = scene.geometry[geom_name]
        if not hasattr(geom, "faces") or len(geom.faces) == 0:
            continue  # point clouds and lines carry no surface
        material = getattr(getattr(geom.visual, "material", None), "name", None) or ""
        v = np.asarray(geom.vertices, dtype=np.float64)
        vertices.append(v @ transform[:3, :3].T + transform[:3, 3])
        faces.append(np.asarray(geom.faces, dtype=np.int64) + offset)
        names.extend([tuple(n for n in (node, geom_name, material) if n)] * len(geom.faces))
        offset += len(v)
    if not faces:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), []
    return np.concatenate(vertices), np.concatenate(faces), names

