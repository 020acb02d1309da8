"""Which wall, window and door faces of an imported building are seen from outside.

Stages (docs/importing.md, "Seen from outside"): a model without any roof face (an office
exported without its roof) is closed by a virtual flat lid at its top over its footprint,
for the rays only, so that the insides of its walls do not see the sky; every facade-class
face above the ground is tested with rays
(:func:`envelope.geometry.visibility.seen_from_outside`); a flat body (a single-face glass
panel) is tested from both sides and turned to face the side that sees out; faces that
other bodies' faces cover (:mod:`dataset.importers.mesh.contact`) or pass through
(:mod:`dataset.importers.mesh.crossings`) are cut there and each piece is decided again, so a
face is never counted whole when part of it lies inside the building.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dataset.importers.import_config import ImportConfig
from dataset.importers.mesh.contact import split_touching_faces
from dataset.importers.mesh.crossings import split_crossing_faces
from dataset.importers.mesh.face_pieces import triangulate_uv
from dataset.rendering.section import cross_section_footprint
from envelope.classes import FACADE_CLASSES, NO_FACADE, SemanticClass
from envelope.geometry.raycast import Raycaster
from envelope.geometry.visibility import escape_fractions, seen_from_outside
from envelope.mesh import LabelledMesh

LID_CLEARANCE_M = 0.01
"""The virtual lid of a roofless model lies this far above its highest point."""


@dataclass(frozen=True)
class Exposure:
    """The building's faces after the cuts, and which are seen from outside.

    Attributes
    ----------
    mesh : LabelledMesh
        The input mesh with cut faces replaced by their pieces and sheet faces seen only
        from behind turned round.
    parent : (F',) int64
        Index of each face's face in the input mesh.
    visible : (F',) bool
        Wall, window and door faces above the ground seen from outside (a twin piece of
        two flush overlapping solids counted once).
    raycaster : Raycaster
        Over ``mesh``.
    turned_sheets : int
        Sheet faces turned round.
    lid : (F',) bool
        The virtual lid's faces (class roof; none unless the input had no roof face), to be
        dropped from the building's mesh once its footprint is cut.
    """

    mesh: LabelledMesh
    parent: np.ndarray
    visible: np.ndarray
    raycaster: Raycaster
    turned_sheets: int
    lid: np.ndarray


def facade_candidates(mesh: LabelledMesh, grade_z_m: float) -> np.ndarray:
    """(F,) bool: wall, window and door faces whose centroid is above the ground."""
    above = mesh.triangles_m[:, :, 2].mean(axis=1) > grade_z_m
    return np.isin(mesh.face_label, [int(c) for c in FACADE_CLASSES]) & above


def exposed_faces(mesh: LabelledMesh, sheet: np.ndarray, grade_z_m: float,
                  config: ImportConfig) -> Exposure:
    """Decide which facade-class faces are seen from outside (module docstring).

    Parameters
    ----------
    mesh
        Bodies oriented outwards (:func:`dataset.importers.mesh.bodies.orient_bodies`), cut at
        the ground (:func:`dataset.importers.mesh.grade.split_at_height`).
    sheet : (F,) bool
        Faces of flat bodies, whose outside is unknown.
    grade_z_m
        Ground height in the mesh's frame.
    config
        Visibility options (:class:`ImportConfig`).
    """
    n_input = len(mesh.faces)
    mesh = _with_lid(mesh, grade_z_m, config)
    sheet = np.concatenate([sheet, np.zeros(len(mesh.faces) - n_input, dtype=bool)])
    mesh, turned = _turn_sheets_to_the_outside(mesh, sheet, grade_z_m, config)
    parent = np.arange(len(mesh.faces))
    raycaster = Raycaster(mesh)
    visible = _seen(raycaster, facade_candidates(mesh, grade_z_m), config)
    # Faces seen from outside that another body's face partly covers: cut them there and
    # decide the pieces (a hidden face's pieces stay hidden; a twin is not counted).
    cut_mesh, cut_parent, twin = split_touching_faces(mesh, visible)
    if len(cut_parent) != len(visible) or twin.any():
        mesh, parent, raycaster, visible = _decide_pieces(
            cut_mesh, cut_parent, parent, visible, grade_z_m, config)
        visible &= ~twin  # counted once, on the earlier solid's face
    # Faces that other faces pass through: cut along the crossings, seen or not (a face
    # mostly inside another solid may be hidden as a whole while a part of it is outside).
    cut_mesh, cut_parent = split_crossing_faces(mesh, facade_candidates(mesh, grade_z_m))
    if len(cut_parent) != len(visible):
        mesh, parent, raycaster, visible = _decide_pieces(
            cut_mesh, cut_parent, parent, visible, grade_z_m, config)
    lid = parent >= n_input
    return Exposure(mesh, np.where(lid, -1, parent), visible, raycaster, turned, lid)


def _with_lid(mesh: LabelledMesh, grade_z_m: float, config: ImportConfig) -> LabelledMesh:
    """The mesh and, if it has no roof face, a flat lid over its footprint's outline (holes
    filled) :data:`LID_CLEARANCE_M` above its highest point, class roof, facing up."""
    if (mesh.face_label == SemanticClass.ROOF).any():
        return mesh
    try:
        footprint = cross_section_footprint(Raycaster(mesh),
                                            grade_z_m + config.footprint_height_m)
    except ValueError:
        return mesh  # no section: the footprint step will say so
    parts = getattr(footprint, "geoms", [footprint])
    outline = [triangulate_uv(type(p)(p.exterior)) for p in parts]
    uv = np.concatenate([t for t in outline if t is not None]).reshape(-1, 3, 2)
    if len(uv) == 0:
        return mesh
    e1, e2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    down = (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]) < 0
    uv[down] = uv[down][:, ::-1]  # counter-clockwise seen from above: facing up
    top = float(mesh.vertices_m[:, 2].max()) + LID_CLEARANCE_M
    corners = np.concatenate([uv, np.full((*uv.shape[:2], 1), top)], axis=2).reshape(-1, 3)
    faces = len(mesh.vertices_m) + np.arange(len(corners)).reshape(-1, 3)
    n = len(faces)
    return LabelledMesh(np.concatenate([mesh.vertices_m, corners]),
                        np.concatenate([mesh.faces, faces]),
                        np.concatenate([mesh.face_label, np.full(n, SemanticClass.ROOF)]),
                        np.concatenate([mesh.face_facade, np.full(n, NO_FACADE)]))


def _decide_pieces(mesh: LabelledMesh, cut_parent: np.ndarray, parent: np.ndarray,
                   visible: np.ndarray, grade_z_m: float, config: ImportConfig):
    """After a cut: faces not cut keep their decision, pieces are decided again."""
    piece = np.bincount(cut_parent)[cut_parent] > 1
    raycaster = Raycaster(mesh)
    seen = visible[cut_parent] & ~piece
    seen |= _seen(raycaster, piece & facade_candidates(mesh, grade_z_m), config)
    return mesh, parent[cut_parent], raycaster, seen


def _turn_sheets_to_the_outside(mesh: LabelledMesh, sheet: np.ndarray, grade_z_m: float,
                                config: ImportConfig) -> tuple[LabelledMesh, int]:
    """Turn round the sheet faces that are seen from outside only from behind."""
    which = sheet & facade_candidates(mesh, grade_z_m)
    if not which.any():
        return mesh, 0
    raycaster = Raycaster(mesh)
    tri = mesh.triangles_m[which]
    normals = raycaster.face_normals[which]
    kwargs = {"rays_per_sample": config.rays_per_sample, "offset_m": config.ray_offset_m,
              "ground": True, "show_progress": False}
    front = escape_fractions(raycaster, tri, normals, **kwargs)
    back = escape_fractions(raycaster, tri, -normals, **kwargs)
    turn = np.zeros(len(mesh.faces), dtype=bool)
    turn[which] = (back >= config.min_escape_fraction) & (back > front)
    if not turn.any():
        return mesh, 0
    faces = mesh.faces.copy()
    faces[turn] = faces[turn][:, ::-1]
    return LabelledMesh(mesh.vertices_m, faces, mesh.face_label, mesh.face_facade), int(turn.sum())


def _seen(raycaster: Raycaster, which: np.ndarray, config: ImportConfig) -> np.ndarray:
    """(F,) bool: faces in ``which`` that enough rays leave."""
    return seen_from_outside(raycaster, which, rays_per_sample=config.rays_per_sample,
                             offset_m=config.ray_offset_m,
                             min_escape_fraction=config.min_escape_fraction, ground=True,
                             show_progress=True)
