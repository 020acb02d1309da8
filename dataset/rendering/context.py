"""What a building's views are rendered from: the building, its textures and, with
``--context``, its neighbours (:class:`envelope.neighbours.Neighbour`) as occluders.

Neighbours are rendered as what a camera in the street sees: their surfaces hide the
building, cast shadows and show their own textures and colours, and in the label images
they are background (class 0, no facade id) with their true depth and normals.

**Cameras stand in the street.** Views are planned on the building alone (a camera far
enough away to frame a whole facade). In a street that spot is often behind or inside the
house opposite, so with context each camera moves forward along its line of sight to the
building until nothing of a neighbour stands between them (:meth:`ViewMeshes.street_pose`:
:data:`CLEARANCE_M` in front of the first neighbour surface on that line), keeping its
direction and lens. A narrow street then gives a close view that no longer frames the
whole facade, as a photograph taken there would. The truth never depends on the context.
"""

from __future__ import annotations

import numpy as np

from dataset.rendering.textures import TextureSet, prepare_textures
from envelope.appearance import concatenate_appearances
from envelope.classes import NO_FACADE, SemanticClass
from envelope.geometry.raycast import Raycaster
from envelope.mesh import LabelledMesh
from envelope.truth import Building

CLEARANCE_M = 0.5
"""A moved camera stands this far in front of the neighbour surface that blocked it."""
MIN_DISTANCE_M = 1.0
"""... but never closer than this to the point of the building it looks at."""


class ViewMeshes:
    """The ray casters and textures of a building's views.

    ``building``: the building (its ``appearance`` and ``context``); ``context``: whether
    its neighbours are rendered. ``alone`` is the building's own caster (views are planned
    on it); ``rendered`` and ``textures`` are what every view is rendered from.
    """

    def __init__(self, building: Building, *, context: bool):
        self.alone = Raycaster(building.mesh)
        neighbours = building.context if context else ()
        self._centre = building.mesh.vertices_m.mean(axis=0)
        self._neighbours = Raycaster(_merged([n.mesh for n in neighbours])) if neighbours else None
        if not neighbours:
            self.rendered = self.alone
        else:
            mesh = _merged([building.mesh, *(n.mesh for n in neighbours)])
            self.rendered = Raycaster(mesh)
        self.textures: TextureSet | None = prepare_textures(concatenate_appearances(
            [(building.appearance, len(building.mesh.faces))]
            + [(n.appearance, len(n.mesh.faces)) for n in neighbours]))

    def street_pose(self, world_from_camera: np.ndarray) -> np.ndarray:
        """(4, 4) pose of a planned view moved in front of the neighbours in its way (module
        docstring); the pose itself when none is, or without context."""
        pose = np.array(world_from_camera, dtype=np.float64)
        if self._neighbours is None:
            return pose
        camera, axis = pose[:3, 3], -pose[:3, 2]
        face, t = self.alone.first_hit(camera[None], axis[None])
        if face[0] >= 0:
            target = camera + t[0] * axis
        else:  # looks past the building: aim at the point of the axis nearest its centre
            target = camera + max(float((self._centre - camera) @ axis), 0.0) * axis
        back = camera - target
        distance = float(np.linalg.norm(back))
        if distance <= MIN_DISTANCE_M:
            return pose
        back /= distance
        face, t = self._neighbours.first_hit(target[None], back[None])
        if face[0] < 0 or t[0] >= distance:
            return pose
        pose[:3, 3] = target + max(float(t[0]) - CLEARANCE_M, MIN_DISTANCE_M) * back
        return pose


def _merged(meshes: list[LabelledMesh]) -> LabelledMesh:
    """``meshes`` as one; every mesh after the first is background (class 0, no facade)."""
    vertices, faces, n = [], [], 0
    for m in meshes:
        vertices.append(m.vertices_m)
        faces.append(m.faces + n)
        n += len(m.vertices_m)
    first, others = meshes[0], sum(len(m.faces) for m in meshes[1:])
    return LabelledMesh(
        np.concatenate(vertices), np.concatenate(faces),
        np.concatenate([first.face_label, np.full(others, int(SemanticClass.BACKGROUND))]),
        np.concatenate([first.face_facade, np.full(others, NO_FACADE)]))
