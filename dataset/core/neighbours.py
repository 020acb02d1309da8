"""The buildings around a building: occluders in its views, never part of its truth.

A source that knows a building's surroundings (the other buildings of a CityGML city model)
gives them as :class:`Neighbour` records beside the building. ``python -m dataset.generate
--context`` renders them in every view (:mod:`dataset.rendering.context`); without it a
building stands alone.
"""

from __future__ import annotations

from dataclasses import dataclass

from dataset.core.appearance import SurfaceAppearance
from dataset.core.mesh import LabelledMesh


@dataclass(frozen=True)
class Neighbour:
    """One building near the measured one, in the measured building's world frame.

    ``mesh``: its surfaces with their own classes (in the label images it is background).
    ``appearance``: its textures and colours, or ``None``.
    """

    name: str
    mesh: LabelledMesh
    appearance: SurfaceAppearance | None = None

    def __post_init__(self) -> None:
        if self.appearance is not None and len(self.appearance.face_material) != len(
                self.mesh.faces):
            raise ValueError("a neighbour's appearance needs one entry per face of its mesh")
