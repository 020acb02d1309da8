"""A triangle mesh whose faces carry a semantic class and a facade id, and its PLY file.

The PLY is binary little-endian with per-face ``label`` (uchar, docs/DESIGN.md class
id) and ``facade`` (int, facade id from 1, or 0 for none) properties, which trimesh, MeshLab
and Blender read. Writing is deterministic: equal meshes give identical bytes.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from envelope.atomic import write_bytes_atomic
from envelope.classes import FACADE_CLASSES, NO_FACADE, NUM_CLASSES

MERGE_DECIMALS = 9
"""Coordinates (m) equal to this many decimals are the same point (~1 nm; exporters print 6-17
digits): merged vertices, canonical outline corners."""


@dataclass(frozen=True)
class LabelledMesh:
    """Triangle mesh in world metres with per-face labels.

    Attributes
    ----------
    vertices_m : (V, 3) float64
        Vertex positions, world frame (z up), metres.
    faces : (F, 3) int64
        Vertex indices, counter-clockwise seen from outside (normals point out).
    face_label : (F,) uint8
        Semantic class id per face (:class:`envelope.classes.SemanticClass`).
    face_facade : (F,) int32
        Facade id per face (from 1), :data:`envelope.classes.NO_FACADE` (0) for none.
    """

    vertices_m: np.ndarray
    faces: np.ndarray
    face_label: np.ndarray
    face_facade: np.ndarray

    def __post_init__(self) -> None:
        v = np.ascontiguousarray(self.vertices_m, dtype=np.float64)
        f = np.ascontiguousarray(self.faces, dtype=np.int64)
        lab = np.ascontiguousarray(self.face_label, dtype=np.uint8)
        fac = np.ascontiguousarray(self.face_facade, dtype=np.int32)
        if v.ndim != 2 or v.shape[1] != 3:
            raise ValueError(f"vertices_m must have shape (V, 3), got {v.shape}")
        if f.ndim != 2 or f.shape[1] != 3:
            raise ValueError(f"faces must have shape (F, 3), got {f.shape}")
        if lab.shape != (len(f),) or fac.shape != (len(f),):
            raise ValueError(
                f"face_label and face_facade need shape ({len(f)},), "
                f"got {lab.shape} and {fac.shape}"
            )
        if len(f) and (f.min() < 0 or f.max() >= len(v)):
            raise ValueError("faces index vertices that do not exist")
        if len(lab) and lab.max() >= NUM_CLASSES:
            raise ValueError(f"face_label holds an unknown class id {int(lab.max())}")
        object.__setattr__(self, "vertices_m", v)
        object.__setattr__(self, "faces", f)
        object.__setattr__(self, "face_label", lab)
        object.__setattr__(self, "face_facade", fac)

    @property
    def triangles_m(self) -> np.ndarray:
        """(F, 3, 3) float64 corner positions of every face."""
        return self.vertices_m[self.faces]

    def face_areas_m2(self) -> np.ndarray:
        """(F,) float64 area of every face in m²."""
        return triangle_areas_m2(self.triangles_m)

    def face_normals(self) -> np.ndarray:
        """(F, 3) float64 outward unit normals (zero for degenerate faces)."""
        return triangle_normals(self.triangles_m)

    def to_trimesh(self):
        """A ``trimesh.Trimesh`` (no processing, so faces keep their order)."""
        import trimesh

        return trimesh.Trimesh(self.vertices_m, self.faces, process=False)


def triangle_normals(triangles_m: np.ndarray) -> np.ndarray:
    """(F, 3) unit normals of (F, 3, 3) triangles (right-hand winding: counter-clockwise seen
    from the side the normal points to); zero for a degenerate triangle."""
    n = np.cross(triangles_m[:, 1] - triangles_m[:, 0], triangles_m[:, 2] - triangles_m[:, 0])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return np.divide(n, length, out=np.zeros_like(n), where=length > 0)


def plane_bases(normals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(F, 3) and (F, 3) unit vectors ``u``, ``v`` spanning each plane, with ``(u, v, n)``
    right-handed for the (F, 3) unit normals ``n`` (zero for a zero normal)."""
    helper = np.where(np.abs(normals[:, 2:3]) < 0.9, [[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]])
    u = np.cross(helper, normals)
    length = np.linalg.norm(u, axis=1, keepdims=True)
    u = np.divide(u, length, out=np.zeros_like(u), where=length > 0)
    return u, np.cross(normals, u)


def triangle_areas_m2(triangles_m: np.ndarray) -> np.ndarray:
    """Areas of triangles.

    Parameters
    ----------
    triangles_m : (n, 3, 3) float
        Corner positions in metres.

    Returns
    -------
    (n,) float64 areas in m².
    """
    t = np.asarray(triangles_m, dtype=np.float64)
    return 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1)


def concatenate_meshes(meshes: list[LabelledMesh]) -> LabelledMesh:
    """Join meshes into one (vertices are not merged)."""
    if not meshes:
        raise ValueError("need at least one mesh to concatenate")
    offsets = np.cumsum([0] + [len(m.vertices_m) for m in meshes[:-1]])
    return LabelledMesh(
        vertices_m=np.concatenate([m.vertices_m for m in meshes]),
        faces=np.concatenate([m.faces + o for m, o in zip(meshes, offsets)]),
        face_label=np.concatenate([m.face_label for m in meshes]),
        face_facade=np.concatenate([m.face_facade for m in meshes]),
    )


def area_by_class_m2(mesh: LabelledMesh, *, facade_id: int | None = None) -> dict[int, float]:
    """Summed face area per facade class id, in m², over faces of one facade or of all facades.

    ``facade_id=None`` sums over every face that belongs to some facade (id >= 1).
    """
    areas = mesh.face_areas_m2()
    keep = mesh.face_facade != NO_FACADE if facade_id is None else mesh.face_facade == facade_id
    return {
        int(c): float(areas[keep & (mesh.face_label == c)].sum()) for c in FACADE_CLASSES
    }


_PLY_HEADER = (
    "ply\n"
    "format binary_little_endian 1.0\n"
    "comment envelope-bench labelled mesh: label = semantic class id, facade = facade id (0 none)\n"
    "element vertex {nv}\n"
    "property double x\nproperty double y\nproperty double z\n"
    "element face {nf}\n"
    "property list uchar int vertex_indices\n"
    "property uchar label\n"
    "property int facade\n"
    "end_header\n"
)
_FACE_DTYPE = np.dtype(
    [("n", "u1"), ("v", "<i4", (3,)), ("label", "u1"), ("facade", "<i4")]
)


def write_labelled_ply(path: str | Path, mesh: LabelledMesh) -> None:
    """Write ``mesh`` as a binary PLY with face ``label`` and ``facade`` (atomically)."""
    header = _PLY_HEADER.format(nv=len(mesh.vertices_m), nf=len(mesh.faces)).encode("ascii")
    faces = np.zeros(len(mesh.faces), dtype=_FACE_DTYPE)
    faces["n"] = 3
    faces["v"] = mesh.faces
    faces["label"] = mesh.face_label
    faces["facade"] = mesh.face_facade
    data = header + mesh.vertices_m.astype("<f8").tobytes() + faces.tobytes()
    write_bytes_atomic(path, data)


def read_labelled_ply(path: str | Path) -> LabelledMesh:
    """Read a PLY with a per-face ``label`` property (and optionally ``facade``).

    Any PLY that trimesh reads works (ASCII or binary, float or double).
    Faces without a ``facade`` property get facade id 0 (none).

    Raises
    ------
    ValueError
        If the file has no face ``label`` property or is not a triangle mesh.
    """
    tm, face_props = read_ply_with_properties(path, "face")
    names = face_props.dtype.names if face_props is not None else ()
    if "label" not in (names or ()):
        raise ValueError(
            f"{path} has no per-face 'label' property; add one holding the class id "
            "(0 background, 1 wall, 2 window, 3 roof, 4 door, 5 other)"
        )
    label = np.asarray(face_props["label"]).reshape(-1)
    facade = (
        np.asarray(face_props["facade"]).reshape(-1)
        if "facade" in names
        else np.full(len(label), NO_FACADE)
    )
    return LabelledMesh(np.asarray(tm.vertices), np.asarray(tm.faces), label, facade)


def read_ply_with_properties(path: str | Path, element: str):
    """A PLY as a ``trimesh.Trimesh`` and the raw per-``element`` properties ("vertex" or "face").

    Returns
    -------
    mesh : trimesh.Trimesh (not processed, so order is kept)
    properties : structured numpy array with one field per property, or ``None``

    Raises
    ------
    ValueError
        If the file is missing or trimesh cannot read it as a mesh.
    """
    import trimesh

    path = Path(path)
    if not path.is_file():
        raise ValueError(f"mesh file {path} does not exist")
    try:
        tm = trimesh.load(path, process=False, force="mesh")
    except Exception as exc:  # trimesh raises many types on bad files
        raise ValueError(f"cannot read {path} as a PLY mesh: {exc}") from exc
    raw = (tm.metadata.get("_ply_raw", {}).get(element, {}) or {}).get("data", None)
    return tm, raw
