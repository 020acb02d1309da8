"""Occluders in front of the facades: trees, cars and people as boxes on the ground.

Occluders are placed once per scene (seeded) and ray-cast with the project's
Embree renderer into every view, so depth, masks and RGB agree across views.
The masks label them background (a segmentation network sees no building
there); the truth (mesh, ``building.json``, facade-id images) is not touched.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dataset.rendering.render import Raycaster
from envelope.camera import Intrinsics, rays_world
from envelope.classes import FACADE_CLASSES, SemanticClass
from envelope.mesh import LabelledMesh

DISTANCE_M = (1.5, 5.0)  # occluder centre in front of the facade plane
CAMERA_CLEARANCE_M = 0.5  # no camera may sit inside an occluder grown by this
_TRIES = 20
_SUN = np.array([0.4, -0.3, 0.87]) / np.linalg.norm([0.4, -0.3, 0.87])

# kind -> boxes (along facade, across, height, base height) in metres, colours (sRGB 0-255)
KINDS: dict[str, tuple[tuple[tuple[float, float, float, float], tuple[int, int, int]], ...]] = {
    "tree": (((0.35, 0.35, 2.5, 0.0), (95, 70, 45)), ((3.0, 3.0, 3.0, 2.5), (60, 110, 50))),
    "car": (((4.4, 1.8, 0.9, 0.2), (150, 30, 35)), ((2.4, 1.6, 0.6, 1.1), (70, 80, 95))),
    "person": (((0.5, 0.35, 1.75, 0.0), (60, 60, 140)),),
}


@dataclass(frozen=True)
class Occluders:
    """Occluder boxes of a scene as one mesh; ``face_rgb`` (F, 3) float in [0, 1] per face."""

    mesh: LabelledMesh
    face_rgb: np.ndarray
    kinds: tuple[str, ...]


def place_occluders(
    building: LabelledMesh, per_facade: float, camera_centres_m: np.ndarray,
    rng: np.random.Generator,
) -> Occluders | None:
    """Boxes on the ground in front of each facade: ``int(per_facade)`` per facade plus one
    with probability ``per_facade % 1``, of a random kind, 1.5-5 m out, anywhere along the
    facade; placements inside the building or around a camera are redrawn (or dropped).
    ``None`` when there is none."""
    inside = Raycaster(building)
    boxes: list[tuple[np.ndarray, np.ndarray, tuple[int, int, int]]] = []
    kinds = []
    facade_face = np.isin(building.face_label, [int(c) for c in FACADE_CLASSES])
    for fid in np.unique(building.face_facade[facade_face & (building.face_facade > 0)]):
        faces = facade_face & (building.face_facade == fid)
        normal, centre, along, extent = _facade_frame(building, faces)
        if normal is None:
            continue
        count = int(per_facade) + int(rng.random() < per_facade % 1)
        for _ in range(count):
            kind = str(rng.choice(list(KINDS)))
            for _ in range(_TRIES):
                base = (centre + normal * rng.uniform(*DISTANCE_M)
                        + along * rng.uniform(*extent))
                parts = [_box(base, along, normal, size) + (colour,)
                         for size, colour in KINDS[kind]]
                if _fits(parts, inside, camera_centres_m):
                    boxes.extend(parts)
                    kinds.append(kind)
                    break
    if not boxes:
        return None
    return _mesh_of(boxes, tuple(kinds))


def render_occluders(
    occluders: Occluders, intrinsics: Intrinsics, world_from_camera: np.ndarray,
    depth_z_m: np.ndarray | None, rgb: np.ndarray, labels: np.ndarray,
    normals: np.ndarray | None,
) -> tuple[np.ndarray, np.ndarray | None, np.ndarray, np.ndarray | None]:
    """Draw occluders into one view's images (new arrays): (rgb, depth, labels, normals).

    A pixel shows an occluder where the occluder's z-depth is smaller than the
    scene's (or the scene has none there). Shapes as in :mod:`envelope.scenes.images`.
    """
    rc = Raycaster(occluders.mesh)
    origins, dirs = rays_world(intrinsics, world_from_camera)
    face, t = rc.first_hit(origins.reshape(-1, 3), dirs.reshape(-1, 3))
    h, w = labels.shape
    face, t = face.reshape(h, w), t.reshape(h, w)
    scene_depth = np.inf if depth_z_m is None else np.where(depth_z_m > 0, depth_z_m, np.inf)
    front = (face >= 0) & (t > 0) & (t < scene_depth)
    f = face[front]
    shade = 0.35 + 0.65 * np.clip(rc.face_normals[f] @ _SUN, 0, 1)
    rgb, labels = rgb.copy(), labels.copy()
    rgb[front] = np.round(occluders.face_rgb[f] * shade[:, None] * 255).astype(np.uint8)
    labels[front] = int(SemanticClass.BACKGROUND)
    if depth_z_m is not None:
        depth_z_m = depth_z_m.copy()
        depth_z_m[front] = t[front]
    if normals is not None:
        normals = normals.copy()
        normals[front] = rc.face_normals[f]
    return rgb, depth_z_m, labels, normals


def _facade_frame(mesh: LabelledMesh, faces: np.ndarray):
    """Outward normal (horizontal), ground-level centre, along-facade axis and extent."""
    tri = mesh.triangles_m[faces]
    area = mesh.face_areas_m2()[faces]
    n = (mesh.face_normals()[faces] * area[:, None]).sum(axis=0)
    n[2] = 0.0
    if np.linalg.norm(n) < 1e-9:
        return None, None, None, None
    n /= np.linalg.norm(n)
    along = np.array([-n[1], n[0], 0.0])
    pts = tri.reshape(-1, 3)
    centre = (tri.mean(axis=1) * area[:, None]).sum(axis=0) / area.sum()
    centre = np.array([centre[0], centre[1], 0.0])
    # The facade's outermost point along its normal: occluders stand in front of it.
    centre += n * float(((pts - centre) @ n).max())
    s = (pts - centre) @ along
    return n, centre, along, (float(s.min()), float(s.max()))


def _box(base: np.ndarray, along: np.ndarray, normal: np.ndarray,
         size: tuple[float, float, float, float]) -> tuple[np.ndarray, np.ndarray]:
    """(8, 3) corners and (12, 3) outward faces of a box standing at ``base``."""
    sx, sy, sz, z0 = size
    up = np.array([0.0, 0.0, 1.0])
    corners = np.array([base + along * x * sx / 2 + normal * y * sy / 2 + up * (z0 + z * sz)
                        for z in (0, 1) for y in (-1, 1) for x in (-1, 1)])
    faces = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
                      [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])
    # Orient every face outward (the handedness of along/normal decides the winding).
    centroid = corners.mean(axis=0)
    tri = corners[faces]
    nrm = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    flip = ((tri.mean(axis=1) - centroid) * nrm).sum(axis=1) < 0
    faces[flip] = faces[flip][:, ::-1]
    return corners, faces


def _fits(parts, inside: Raycaster, cameras_m: np.ndarray) -> bool:
    for corners, _, _ in parts:
        probe = np.vstack([corners, corners.mean(axis=0)])
        probe[:, 2] = np.maximum(probe[:, 2], 0.05)
        if inside.contains(probe).any():
            return False
        lo, hi = corners.min(axis=0) - CAMERA_CLEARANCE_M, corners.max(axis=0) + CAMERA_CLEARANCE_M
        if len(cameras_m) and ((cameras_m >= lo) & (cameras_m <= hi)).all(axis=1).any():
            return False
    return True


def _mesh_of(boxes, kinds: tuple[str, ...]) -> Occluders:
    vertices, faces, colours = [], [], []
    for i, (corners, box_faces, colour) in enumerate(boxes):
        vertices.append(corners)
        faces.append(box_faces + 8 * i)
        colours.append(np.tile(np.asarray(colour, float) / 255.0, (len(box_faces), 1)))
    f = np.vstack(faces)
    mesh = LabelledMesh(np.vstack(vertices), f, np.zeros(len(f), np.uint8),
                        np.zeros(len(f), np.int32))
    return Occluders(mesh, np.vstack(colours), kinds)
