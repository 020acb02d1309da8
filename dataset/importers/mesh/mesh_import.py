"""A user's own labelled building mesh -> :class:`envelope.truth.Building` with derived truth.

Steps (docs/importing.md): read the file (:mod:`dataset.importers.mesh.mesh_files`); check it
carries
facade classes; move it to the origin with its ground at z = 0; turn each body to face
outwards (:mod:`dataset.importers.mesh.bodies`: closed, open, inside-out and single-face bodies
are all normal input); cut the faces that cross the ground (:mod:`dataset.importers.mesh.grade`);
find the wall/window/door faces above the ground seen from outside, cutting faces where
other bodies touch or pass through them (:mod:`dataset.importers.mesh.exposure`); group them into
facades (:mod:`dataset.importers.mesh.facade_grouping`); sum areas per class and facade; cut the
footprint ``footprint_height_m`` above the ground (:mod:`dataset.rendering.section`).
"""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path

import numpy as np

from dataset.importers.import_config import ImportConfig
from dataset.importers.mesh.bodies import orient_bodies
from dataset.importers.mesh.exposure import exposed_faces, facade_candidates
from dataset.importers.mesh.facade_grouping import FacadeGroup, facade_ids_of_faces, group_facades
from dataset.importers.mesh.grade import split_at_height
from dataset.importers.mesh.mesh_files import merge_vertices, read_labelled_mesh_file
from dataset.rendering.section import cross_section_footprint
from envelope.classes import FACADE_CLASSES, NO_FACADE, SemanticClass
from envelope.footprint import polygon_to_geojson
from envelope.mesh import LabelledMesh
from envelope.truth import Building, BuildingTruth, FacadeTruth
from envelope.wwr import ClassAreas

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
        other; :func:`dataset.importers.mesh.mesh_files.class_from_name`). Metres.
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
        Unreadable, empty, unlabelled, unknown class names, no facade classes, no facade
        seen from outside, or no footprint. Open, overlapping, inside-out and single-face
        bodies are accepted (counted in ``truth.extra["bodies"]``).
    """
    path = Path(path)
    config = ImportConfig() if config is None else config
    mesh = read_labelled_mesh_file(path, up_axis=config.up_axis)
    building, _ = building_from_mesh(
        mesh, building_id=building_id if building_id is not None else path.stem,
        source=path, config=config,
    )
    return building


class NoFacadeError(ValueError):
    """No wall, window or door face above the ground is seen from outside.

    ``facade_class_parents`` are the facade-class faces above the ground (indices into the
    mesh given to :func:`building_from_mesh`), for a caller that can name their elements."""

    def __init__(self, message: str, facade_class_parents: np.ndarray):
        super().__init__(message)
        self.facade_class_parents = facade_class_parents


class NoFootprintError(ValueError):
    """The footprint section cuts no solid; ``section_parents`` are the faces (indices into
    the input mesh) that cross its height."""

    def __init__(self, message: str, section_parents: np.ndarray):
        super().__init__(message)
        self.section_parents = section_parents


def building_from_mesh(
    mesh: LabelledMesh,
    *,
    building_id: str,
    source: Path,
    config: ImportConfig | None = None,
    body_group: np.ndarray | None = None,
    extra: dict | None = None,
) -> tuple[Building, np.ndarray]:
    """Derive a building's ground truth from its labelled mesh (z up, metres).

    Parameters
    ----------
    mesh
        The building's bodies: closed or open, touching or overlapping, any orientation,
        vertices merged or not.
    building_id
        The truth's ``id``.
    source
        The file it came from (named in errors and in the truth).
    config
        :class:`ImportConfig` (default: its defaults); ``ground_z_m`` is in the mesh's frame.
    body_group : (F,) int, optional
        Element of each face (an IFC product): a body never spans two elements.
    extra
        More entries for the truth's ``extra``.

    Returns
    -------
    building
        Mesh moved to the origin (ground at z = 0 unless ``recentre`` is off), faces that
        cross the ground cut there, facade ids 1..N; truth of type ``"imported"`` counting
        only faces above the ground and seen from outside. ``truth.extra["bodies"]`` counts
        the bodies found (closed, open, sheets, turned inside out, rewound).
    parent : (F',) int64
        Index of each of its faces in ``mesh``.

    Raises
    ------
    ValueError
        No faces or no facade classes; :class:`NoFacadeError`; :class:`NoFootprintError`.
    """
    config = ImportConfig() if config is None else config
    mesh, kept = _drop_collapsed_faces(mesh)
    _check_mesh(source, mesh)
    vertices = mesh.vertices_m
    ground_z = float(vertices[:, 2].min()) if config.ground_z_m is None else config.ground_z_m
    offset = np.zeros(3)
    if config.recentre:
        lo, hi = vertices.min(axis=0), vertices.max(axis=0)
        offset = -np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, ground_z])
        vertices = vertices + offset
    bodies = orient_bodies(vertices, mesh.faces,
                           None if body_group is None else np.asarray(body_group)[kept])
    grade_z = ground_z + offset[2]
    mesh, parent = split_at_height(
        LabelledMesh(vertices, bodies.faces, mesh.face_label, mesh.face_facade), grade_z)
    exposure = exposed_faces(mesh, bodies.sheet[parent], grade_z, config)
    mesh, visible, raycaster = exposure.mesh, exposure.visible, exposure.raycaster
    parent = np.where(exposure.lid, -1, kept[parent[np.maximum(exposure.parent, 0)]])
    vertices, faces = mesh.vertices_m, mesh.faces
    areas, normals = mesh.face_areas_m2(), mesh.face_normals()
    is_facade_class = np.isin(mesh.face_label, [int(c) for c in FACADE_CLASSES])
    candidate = facade_candidates(mesh, grade_z)
    groups = group_facades(
        mesh.triangles_m, normals, areas, visible,
        max_tilt_deg=config.max_tilt_deg,
        angle_tolerance_deg=config.angle_tolerance_deg,
        offset_tolerance_m=config.offset_tolerance_m,
        gap_tolerance_m=config.gap_tolerance_m,
        min_width_m=config.min_facade_width_m,
    )
    if not groups:
        raise _no_facade_error(source, mesh, areas, candidate, visible, ground_z, config,
                               parent)
    face_facade = facade_ids_of_faces(groups, len(faces))
    labels = mesh.face_label
    mesh = LabelledMesh(vertices, faces, labels, face_facade)

    facades = tuple(
        _facade_truth(i + 1, g, mesh, areas, normals) for i, g in enumerate(groups)
    )
    height_m = float(mesh.triangles_m[~exposure.lid][:, :, 2].max()) - grade_z
    footprint = _footprint(source, raycaster, grade_z, ground_z, config, parent)
    # The virtual lid of a roofless model served the rays and the footprint; the file's
    # own faces remain.
    mesh = LabelledMesh(vertices, faces[~exposure.lid], labels[~exposure.lid],
                        face_facade[~exposure.lid])
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
            "hidden_area_m2": _class_areas(labels, areas, candidate & ~visible),
            "below_grade_area_m2": _class_areas(labels, areas, is_facade_class & ~candidate),
            "unassigned_area_m2": _class_areas(
                labels, areas, visible & (face_facade == NO_FACADE)
            ),
            "bodies": {**bodies.counts, "sheet_faces_turned": exposure.turned_sheets,
                       "virtual_lid": bool(exposure.lid.any())},
            "import_config": asdict(config),
            **(extra or {}),
        },
    )
    return Building(mesh=mesh, truth=truth), parent[~exposure.lid]


def _footprint(source: Path, raycaster, grade_z: float, ground_z: float,
               config: ImportConfig, parent: np.ndarray):
    """The section ``footprint_height_m`` above the ground, or :class:`NoFootprintError`."""
    z = grade_z + config.footprint_height_m
    try:
        return cross_section_footprint(raycaster, z)
    except ValueError:
        tri_z = raycaster.mesh.triangles_m[:, :, 2]
        crossing = np.unique(parent[(tri_z.min(axis=1) < z) & (tri_z.max(axis=1) > z)])
        raise NoFootprintError(
            f"{source}: no footprint: the section {config.footprint_height_m} m above the "
            f"ground (z = {ground_z + config.footprint_height_m:.3f} m in the file) cuts "
            f"no solid body ({len(crossing)} faces cross that height). Set the ground "
            "(--ground-z) to the building's ground floor, or the section height "
            "(--footprint-height-m) to a height where its outer walls stand", crossing
        ) from None


def _no_facade_error(source: Path, mesh: LabelledMesh, areas: np.ndarray,
                     candidate: np.ndarray, visible: np.ndarray, ground_z: float,
                     config: ImportConfig, parent: np.ndarray) -> NoFacadeError:
    hidden = float(areas[candidate & ~visible].sum())
    below = float(areas[np.isin(mesh.face_label, [int(c) for c in FACADE_CLASSES])
                        & ~candidate].sum())
    return NoFacadeError(
        f"{source}: no facade: {hidden:.1f} m² of wall, window and door faces lie above the "
        f"ground (z = {ground_z:.3f} m in the file) and {below:.1f} m² below it, but no "
        f"upright stretch of them at least {config.min_facade_width_m} m wide is seen from "
        "outside. Set the ground (--ground-z) to the building's ground floor, and label "
        "the outer surfaces of the walls, windows and doors as such",
        np.unique(parent[candidate]))


def _drop_collapsed_faces(mesh: LabelledMesh) -> tuple[LabelledMesh, np.ndarray]:
    """Without faces that vertex merging makes a line or a point; and the kept faces' indices."""
    f = merge_vertices(mesh.vertices_m, mesh.faces)[1]
    keep = np.flatnonzero((f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 2] != f[:, 0]))
    if len(keep) == len(f):
        return mesh, keep
    return LabelledMesh(mesh.vertices_m, mesh.faces[keep], mesh.face_label[keep],
                        mesh.face_facade[keep]), keep


def _check_mesh(path: Path, mesh: LabelledMesh) -> None:
    if len(mesh.faces) == 0:
        raise ValueError(f"{path} holds no faces; export the building's surfaces as triangles")
    if not np.isin(mesh.face_label, [int(c) for c in FACADE_CLASSES]).any():
        raise ValueError(
            f"{path} has no wall, window or door faces (labels present: "
            f"{', '.join(SemanticClass(c).name.lower() for c in np.unique(mesh.face_label))}); "
            "label the facade surfaces wall, window or door"
        )


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


def _class_areas(labels: np.ndarray, areas: np.ndarray, keep: np.ndarray) -> dict[str, float]:
    return {c.name.lower(): float(areas[keep & (labels == c)].sum()) for c in FACADE_CLASSES}
