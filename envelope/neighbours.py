"""A building's surroundings: the buildings around it (occluders in its views) and the streets
a capture vehicle drives along; never part of its truth.

A source that knows a building's surroundings (the other buildings of a CityGML city model)
gives them as :class:`Neighbour` records beside the building. ``python -m dataset.generate
--context`` renders them in every view (:mod:`dataset.rendering.context`); without it a
building stands alone. A source with a road network (the ``lod3`` preset's OpenDRIVE file)
gives its lanes as :class:`Street` lines, where ``--street`` places its cameras
(:mod:`dataset.rendering.street_views`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from envelope.appearance import SurfaceAppearance
from envelope.mesh import LabelledMesh


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


@dataclass(frozen=True)
class Street:
    """A line a capture vehicle drives along (a lane's centre line), in the measured
    building's world frame: ``points_m`` (N, 3), N >= 2, in the lane's order; ``name`` says
    where it comes from (e.g. ``road 1444000 lane -2``)."""

    name: str
    points_m: np.ndarray

    def __post_init__(self) -> None:
        pts = np.asarray(self.points_m, dtype=np.float64)
        if pts.ndim != 2 or pts.shape[1] != 3 or len(pts) < 2 or not np.isfinite(pts).all():
            raise ValueError(f"street {self.name!r} needs (N >= 2, 3) finite points, got "
                             f"shape {pts.shape}")
        object.__setattr__(self, "points_m", pts)
