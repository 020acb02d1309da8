"""A user's own labelled building mesh -> :class:`dataset.core.truth.Building` with derived truth.

Steps (docs/importing.md): read the file (:mod:`dataset.importers.mesh_files`); check its bodies are
closed and consistently oriented (they may touch or overlap) and carry facade classes; move
it to the origin with its ground at z = 0 and cut the faces that cross the ground
(:mod:`dataset.importers.grade`) and where another body's face lies against them
(:mod:`dataset.importers.contact`); find the wall/window/door faces above the ground seen from
outside
(:mod:`dataset.rendering.visibility`, through :mod:`dataset.rendering.raycast`); group them into
facades
(:mod:`dataset.importers.facade_grouping`); sum areas per class and facade; cut the footprint
``footprint_height_m`` above the ground (:mod:`dataset.rendering.section`).
"""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path

import numpy as np

from dataset.core.classes import FACADE_CLASSES, NO_FACADE, SemanticClass
from dataset.core.footprint import polygon_to_geojson
from dataset.core.mesh import LabelledMesh
from dataset.core.truth import Building, BuildingTruth, FacadeTruth
from dataset.core.wwr import ClassAreas
from dataset.importers.contact import split_touching_faces
from dataset.importers.facade_grouping import FacadeGroup, facade_ids_of_faces, group_facades
from dataset.importers.grade import edge_balance, split_at_height
from dataset.importers.import_config import (
    ImportConfig,
)
from dataset.importers.mesh_files import merge_vertices, read_labelled_mesh_file
from dataset.rendering.raycast import Raycaster
from dataset.rendering.section import cross_section_footprint
from dataset.rendering.visibility import seen_from_outside

CURVED_SPREAD_DEG = 1.0  # a facade whose face normals spread wider than this is curved


def import_labelled_mesh(
    path: str | Path, *, building_id: str | None = None, config: ImportConfig | None = None
) -> Building:
    """Read a user's labelled building mesh and derive its ground truth.

    Parameters
    ----------
    path
        ``.ply`` with a per-face ``label`` (class id), or ``.obj``/``.glb``/``.gltf`` whose
        objects, groups or materials are named after the classes (wall, window, roof, door,
        other; :func:`dataset.importers.mesh_files.class_from_name`). Metres.
    building_id
        The truth's ``id``; default the file name without suffix.
    config
        Tolerances and options, :class:`ImportConfig` (default: its defaults).

    Returns
    -------
    Building as :func:`building_from_mesh` makes it.

    Raises
    ------
    ValueError
        Unreadable, empty, unlabelled, unknown class names, not closed, inconsistently
        oriented, no facade classes, or no facade seen from outside.
    """
    path = Path(path)
    config = ImportConfig() if config is None else config
    mesh = read_labelled_mesh_file(path, up_axis=config.up_axis)
    building, _ = building_from_mesh(
        mesh, building_id=building_id if building_id is not None else path.stem,
        source=path, config=config,
    )
    return building


def building_from_mesh(
    mesh: LabelledMesh,
    *,
    building_id: str,
    source: Path,
    config: ImportConfig | None = None,
    require_closed: bool = True,
    extra: dict | None = None,
) -> tuple[Building, np.ndarray]:
    """Derive a building's ground truth from its labelled mesh (z up, metres).

    Parameters
    ----------
    mesh
        Closed bodies that may touch or overlap (vertices merged or not).
    building_id
        The truth's ``id``.
    source
        The file it came from (named in errors and in the truth).
    config
        :class:`ImportConfig` (default: its defaults); ``ground_z_m`` is in the mesh's frame.
    require_closed
        Refuse a mesh whose bodies are not closed; when False, the edge counts are
        recorded in ``truth.extra["open_edges"]`` instead.
    extra
        More entries for the truth's ``extra``.

    Returns
    -------
    building
        Mesh moved to the origin (ground at z = 0 unless ``recentre`` is off), faces that
        cross the ground cut there, facade ids 1..N; truth of type ``"imported"`` counting
        only faces above the ground and seen from outside.
    parent : (F',) int64
        Index of each of its faces in ``mesh``.
    """
    config = ImportConfig() if config is None else config
    mesh, kept = _drop_collapsed_faces(mesh)
    open_edges = _check_mesh(source, mesh, require_closed=require_closed)
    vertices, faces = mesh.vertices_m, mesh.faces
    ground_z = float(vertices[:, 2].min()) if config.ground_z_m is None else config.ground_z_m
    offset = np.zeros(3)
    if config.recentre:
        lo, hi = vertices.min(axis=0), vertices.max(axis=0)
        offset = -np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, ground_z])
        vertices = vertices + offset
    if _signed_volume_m3(vertices, faces) < 0:  # inside-out export: every normal points in
        faces = faces[:, ::-1].copy()
    grade_z = ground_z + offset[2]
    mesh, parent = split_at_height(
        LabelledMesh(vertices, faces, mesh.face_label, mesh.face_facade), grade_z
    )
    parent = kept[parent]
    candidate = _facade_candidates(mesh, grade_z)
    raycaster = Raycaster(mesh)
    visible = _seen_from_outside(raycaster, candidate, config)
    # Faces seen from outside that another body's face partly covers: cut them there and
    # decide the pieces (a hidden face's pieces stay hidden; a twin is not counted).
    mesh, touching_parent, twin = split_touching_faces(mesh, visible)
    if len(touching_parent) != len(visible) or twin.any():
        parent = parent[touching_parent]
        piece = np.bincount(touching_parent)[touching_parent] > 1
        raycaster = Raycaster(mesh)
        visible = visible[touching_parent] & ~piece
        visible |= _seen_from_outside(raycaster, piece & _facade_candidates(mesh, grade_z),
                                      config)
        visible &= ~twin  # counted once, on the earlier solid's face
    vertices, faces = mesh.vertices_m, mesh.faces
    areas, normals = mesh.face_areas_m2(), mesh.face_normals()
    is_facade_class = np.isin(mesh.face_label, [int(c) for c in FACADE_CLASSES])
    candidate = _facade_candidates(mesh, grade_z)
    groups = group_facades(
        mesh.triangles_m, normals, areas, visible,
        max_tilt_deg=config.max_tilt_deg,
        angle_tolerance_deg=config.angle_tolerance_deg,
        offset_tolerance_m=config.offset_tolerance_m,
        gap_tolerance_m=config.gap_tolerance_m,
        min_width_m=config.min_facade_width_m,
    )
    if not groups:
        raise ValueError(
            f"{source}: no wall, window or door faces above the ground (z = {ground_z:.3f} m), "
            f"upright and seen from outside form a facade at least {config.min_facade_width_m} "
            "m wide; check the labels, the ground height and that the normals point outwards"
        )
    face_facade = facade_ids_of_faces(groups, len(faces))
    mesh = LabelledMesh(vertices, faces, mesh.face_label, face_facade)

    facades = tuple(
        _facade_truth(i + 1, g, mesh, areas, normals) for i, g in enumerate(groups)
    )
    height_m = float(vertices[:, 2].max()) - grade_z
    footprint = cross_section_footprint(raycaster, grade_z + config.footprint_height_m)
    window, wall, door = (sum(getattr(f, k) for f in facades)
                          for k in ("window_area_m2", "wall_area_m2", "door_area_m2"))
    totals = ClassAreas(window, wall, door)
    truth = BuildingTruth(
        id=building_id,
        type="imported",
        floors=max(1, round(height_m / config.floor_height_m)),
        height_m=height_m,
        window_area_m2=window,
        facade_area_m2=totals.gross_m2,
        wall_area_m2=wall,
        door_area_m2=door,
        wwr=totals.wwr,
        footprint=polygon_to_geojson(footprint),
        footprint_area_m2=float(footprint.area),
        facades=facades,
        name=source.name,
        extra={
            "source_file": source.name,
            "offset_m": [float(x) for x in offset],
            "ground_z_m": ground_z,
            "hidden_area_m2": _class_areas(mesh, areas, candidate & ~visible),
            "below_grade_area_m2": _class_areas(mesh, areas, is_facade_class & ~candidate),
            "unassigned_area_m2": _class_areas(
                mesh, areas, visible & (face_facade == NO_FACADE)
            ),
            **({} if require_closed else {"open_edges": open_edges}),
            "import_config": asdict(config),
            **(extra or {}),
        },
    )
    return Building(mesh=mesh, truth=truth), parent


def _facade_candidates(mesh: LabelledMesh, grade_z_m: float) -> np.ndarray:
    """(F,) bool: wall, window and door faces above the ground."""
    above = mesh.triangles_m[:, :, 2].mean(axis=1) > grade_z_m
    return np.isin(mesh.face_label, [int(c) for c in FACADE_CLASSES]) & above


def _seen_from_outside(raycaster: Raycaster, which: np.ndarray, config: ImportConfig
                       ) -> np.ndarray:
    """(F,) bool: faces in ``which`` that enough rays leave
    (:func:`dataset.rendering.visibility.seen_from_outside`)."""
    return seen_from_outside(raycaster, which, rays_per_sample=config.rays_per_sample,
                             offset_m=config.ray_offset_m,
                             min_escape_fraction=config.min_escape_fraction, ground=True,
                             show_progress=True)


def _drop_collapsed_faces(mesh: LabelledMesh) -> tuple[LabelledMesh, np.ndarray]:
    """Without faces that vertex merging makes a line or a point; and the kept faces' indices."""
    f = merge_vertices(mesh.vertices_m, mesh.faces)[1]
    keep = np.flatnonzero((f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 2] != f[:, 0]))
    if len(keep) == len(f):
        return mesh, keep
    return LabelledMesh(mesh.vertices_m, mesh.faces[keep], mesh.face_label[keep],
                        mesh.face_facade[keep]), keep


def _check_mesh(path: Path, mesh: LabelledMesh, *, require_closed: bool) -> dict[str, int]:
    if len(mesh.faces) == 0:
        raise ValueError(f"{path} holds no faces; export the building's surfaces as triangles")
    if not np.isin(mesh.face_label, [int(c) for c in FACADE_CLASSES]).any():
        raise ValueError(
            f"{path} has no wall, window or door faces (labels present: "
            f"{', '.join(SemanticClass(c).name.lower() for c in np.unique(mesh.face_label))}); "
            "label the facade surfaces wall, window or door"
        )
    n_open, n_flipped = edge_balance(merge_vertices(mesh.vertices_m, mesh.faces)[1])
    if require_closed and n_open:
        raise ValueError(
            f"{path} is not a closed mesh: {n_open} open edge(s); every body (wall, window, "
            "slab solid) must enclose a volume -- close its holes and snap T-junctions in the "
            "authoring tool (Blender: select the body, 'Merge by Distance', 'Fill Holes'); "
            "bodies may touch or overlap"
        )
    if require_closed and n_flipped:
        raise ValueError(
            f"{path}: faces are not consistently oriented ({n_flipped} edge(s) walked twice "
            "the same way: some normals point inwards); recalculate normals outside in the "
            "authoring tool (Blender: Mesh > Normals > Recalculate Outside)"
        )
    return {"open": n_open, "misoriented": n_flipped}


def _signed_volume_m3(vertices_m: np.ndarray, faces: np.ndarray) -> float:
    t = vertices_m[faces]
    return float(np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6.0)


def _facade_truth(
    facade_id: int, group: FacadeGroup, mesh: LabelledMesh, areas: np.ndarray, normals: np.ndarray
) -> FacadeTruth:
    f = group.face_index
    by_class = {
        c: float(areas[f][mesh.face_label[f] == c].sum()) for c in FACADE_CLASSES
    }
    window, wall, door = (by_class[SemanticClass.WINDOW], by_class[SemanticClass.WALL],
                          by_class[SemanticClass.DOOR])
    facade_areas = ClassAreas(window, wall, door)
    gross = facade_areas.gross_m2
    z = mesh.triangles_m[f][:, :, 2]
    height = float(z.max() - z.min())
    h = normals[f, :2] / np.linalg.norm(normals[f, :2], axis=1, keepdims=True)
    spread = np.degrees(np.arccos(np.clip(h @ np.asarray(group.normal[:2]), -1.0, 1.0)).max())
    curved = bool(spread > CURVED_SPREAD_DEG)
    # A curved facade's width is its mean width (area / height), not its chord.
    width = gross / height if curved else group.along_m[1] - group.along_m[0]
    return FacadeTruth(
        id=facade_id,
        normal=group.normal,
        width_m=float(width),
        height_m=height,
        window_area_m2=window,
        wall_area_m2=wall,
        door_area_m2=door,
        facade_area_m2=gross,
        wwr=facade_areas.wwr,
        curved=curved,
    )


def _class_areas(mesh: LabelledMesh, areas: np.ndarray, keep: np.ndarray) -> dict[str, float]:
    return {
        c.name.lower(): float(areas[keep & (mesh.face_label == c)].sum()) for c in FACADE_CLASSES
    }
