"""Where each facade is, read off the labelled mesh: centre, axes, extent and corners.

Camera placement for facade views works from these patches, so an imported
mesh (whose facades only exist as face ids) gets the same views as a generated
building. A planar facade is one patch with the normal from the truth; a curved
facade (``FacadeTruth.curved``) is cut into angular sectors of at most
``sector_deg`` of face-normal azimuth, one patch each, all with the facade's id.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from envelope.classes import NO_FACADE
from envelope.truth import Building

_UP = np.array([0.0, 0.0, 1.0])
# A facade normal needs at least this much horizontal length to define a wall
# direction; a roof-like "facade" is skipped with a warning.
_MIN_HORIZONTAL = 0.3


@dataclass(frozen=True)
class FacadePatch:
    """A (part of a) facade seen as a rectangle in its own plane.

    Attributes
    ----------
    facade_id : int
    normal : (3,) float64
        Outward unit normal, horizontal.
    right : (3,) float64
        Unit vector along the wall, to the right for a viewer facing the facade (``up x normal``).
    centre_m : (3,) float64
        Centre of the rectangle, in the facade's front-most plane.
    width_m, height_m : float
        Extent of the facade's faces along ``right`` and along world z.
    corners_m : (4, 3) float64
        Bottom-left, bottom-right, top-right, top-left (seen from outside), front plane.
    face_index : (F,) int64
        Mesh faces of this patch.
    """

    facade_id: int
    normal: np.ndarray
    right: np.ndarray
    centre_m: np.ndarray
    width_m: float
    height_m: float
    corners_m: np.ndarray
    face_index: np.ndarray


def facade_patches(building: Building, *, sector_deg: float = 60.0) -> list[FacadePatch]:
    """Patches of every facade id that has faces in the mesh, sorted by facade id.

    Normals come from the truth where it lists the facade, else from the
    area-weighted mean of the facade's face normals. Facades whose normal is not
    close to horizontal are skipped with a warning.
    """
    if not 0 < sector_deg <= 180:
        raise ValueError(f"sector_deg must be in (0, 180], got {sector_deg}")
    mesh = building.mesh
    truth = {f.id: f for f in building.truth.facades}
    face_normals = mesh.face_normals()
    areas = mesh.face_areas_m2()
    patches = []
    for facade_id in np.unique(mesh.face_facade):
        if facade_id == NO_FACADE:
            continue
        faces = np.flatnonzero(mesh.face_facade == facade_id)
        known = truth.get(int(facade_id))
        if known is not None and known.curved:
            groups = _sectors(faces, face_normals, areas, sector_deg)
        else:
            normal = (np.asarray(known.normal, float) if known is not None
                      else (face_normals[faces] * areas[faces, None]).sum(axis=0))
            groups = [(faces, normal)]
        for group, normal in groups:
            patch = _patch(building, int(facade_id), group, normal)
            if patch is not None:
                patches.append(patch)
    return patches


def _sectors(
    faces: np.ndarray, face_normals: np.ndarray, areas: np.ndarray, sector_deg: float
) -> list[tuple[np.ndarray, np.ndarray]]:
    """Split a curved facade's faces by the azimuth of their normals into equal sectors."""
    n = face_normals[faces]
    azimuth = np.arctan2(n[:, 1], n[:, 0])
    # Start the sweep in the widest gap between normals so no sector wraps around it.
    order = np.sort(azimuth)
    gaps = np.diff(np.concatenate([order, order[:1] + 2 * np.pi]))
    start = order[(np.argmax(gaps) + 1) % len(order)]
    rel = np.mod(azimuth - start, 2 * np.pi)
    span = float(rel.max())
    count = max(1, int(np.ceil(np.rad2deg(span) / sector_deg - 1e-9)))
    which = np.minimum((rel / (span / count if span > 0 else 1.0)).astype(int), count - 1)
    groups = []
    for k in range(count):
        group = faces[which == k]
        if len(group):
            groups.append((group, (face_normals[group] * areas[group, None]).sum(axis=0)))
    return groups


def _patch(
    building: Building, facade_id: int, faces: np.ndarray, normal: np.ndarray
) -> FacadePatch | None:
    horizontal = np.array([normal[0], normal[1], 0.0])
    length = np.linalg.norm(horizontal)
    if length < _MIN_HORIZONTAL * max(np.linalg.norm(normal), 1e-12):
        warnings.warn(
            f"building {building.truth.id}: facade {facade_id} has no horizontal normal "
            f"({np.round(normal, 3).tolist()}); it gets no facade views",
            stacklevel=3,
        )
        return None
    n = horizontal / length
    right = np.cross(_UP, n)
    points = building.mesh.vertices_m[np.unique(building.mesh.faces[faces])]
    s = points @ right
    z = points[:, 2]
    front = float((points @ n).max())
    s0, s1, z0, z1 = s.min(), s.max(), z.min(), z.max()
    corners = np.array([
        s0 * right + z0 * _UP, s1 * right + z0 * _UP, s1 * right + z1 * _UP, s0 * right + z1 * _UP
    ]) + front * n
    return FacadePatch(
        facade_id=facade_id,
        normal=n,
        right=right,
        centre_m=corners.mean(axis=0),
        width_m=float(s1 - s0),
        height_m=float(z1 - z0),
        corners_m=corners,
        face_index=faces,
    )
