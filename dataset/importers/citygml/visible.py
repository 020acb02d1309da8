"""What of each CityGML facade is seen straight on: its ``visible_*_area_m2`` truth.

The definition is the procedural buildings' (:mod:`dataset.families.visible_facade`): a
point of a facade is visible when the ray from it along the facade's outward normal meets
no other surface of the building. Here the facade is its regions in its reference plane
(:class:`dataset.importers.citygml.facades.FacadeRegions`: the areas the truth counts, a
window's hundred polygons as one region), and the other surfaces are every mesh triangle
of another facade or of none: balconies and loggias (installations), bays, roof overhangs,
walls in front. The facade's own walls and openings (frames and sills in front of the
glass included) hide nothing of it.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from dataset.families.building_assembly import HIDDEN_NOISE_M2
from dataset.families.visible_facade import front_shadow
from dataset.importers.citygml.facades import FacadeRegions
from envelope.classes import SemanticClass
from envelope.mesh import LabelledMesh
from envelope.truth import FacadeTruth

_UP = np.array([0.0, 0.0, 1.0])


def with_visible_areas(truths: tuple[FacadeTruth, ...], mesh: LabelledMesh,
                       regions: dict[int, FacadeRegions]) -> tuple[FacadeTruth, ...]:
    """``truths`` with their areas seen straight on.

    truths : the covered facades' truth (ids from 1); mesh : the building's labelled mesh
    (face facade ids as in ``truths``); regions : facade id -> its regions.
    """
    out = []
    for f in truths:
        hidden = _hidden_m2(mesh, mesh.face_facade != f.id, regions[f.id])
        out.append(replace(
            f, visible_window_area_m2=_less(f.window_area_m2, hidden["window"]),
            visible_wall_area_m2=_less(f.wall_area_m2, hidden["wall"]),
            visible_door_area_m2=_less(f.door_area_m2, hidden["door"])))
    return tuple(out)


def hidden_share(truths: tuple[FacadeTruth, ...], mesh: LabelledMesh,
                 regions: dict[int, FacadeRegions], label: SemanticClass) -> float:
    """Share of the facades' gross area (wall + window + door) that the mesh's faces of
    class ``label`` hide seen straight on (0 without facades)."""
    gross = sum(f.facade_area_m2 for f in truths)
    if gross <= 0:
        return 0.0
    hidden = sum(sum(_hidden_m2(mesh, (mesh.face_facade != f.id) & (mesh.face_label == label),
                                regions[f.id]).values()) for f in truths)
    return hidden / gross


def _hidden_m2(mesh: LabelledMesh, occluders: np.ndarray, r: FacadeRegions) -> dict[str, float]:
    """Window, wall and door area of the facade ``r`` that ``occluders`` (F,) hide."""
    shadow = front_shadow(mesh.triangles_m, occluders, r.offset_m * r.normal, r.normal,
                          np.stack([r.tangent, _UP]), r.gross.bounds)
    return {name: 0.0 if shadow.is_empty else float(getattr(r, name).intersection(shadow).area)
            for name in ("window", "wall", "door")}


def _less(area_m2: float, hidden_m2: float) -> float:
    """``area_m2 - hidden_m2``; a hidden area under :data:`HIDDEN_NOISE_M2` is round-off."""
    return float(area_m2) if hidden_m2 < HIDDEN_NOISE_M2 else max(0.0, area_m2 - hidden_m2)
