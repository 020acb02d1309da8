"""Walls + other faces -> :class:`envelope.truth.Building` with analytic ground truth.

Per-facade truth is summed from each wall's parameters (outline area, opening
sizes, contact rectangles), never from the triangulated mesh, so that tests can
hold one against the other. Only the part of each facade that other surfaces
hide from the front (:mod:`dataset.families.visible_facade`) needs the mesh: the
visible areas are the analytic ones less that.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from shapely.geometry import Polygon

from dataset.families.facade_geometry import WallSpec, wall_faces
from dataset.families.polygon_mesh import PlanarFace, triangulate_faces
from dataset.families.visible_facade import hidden_facade_areas_m2
from envelope.classes import SemanticClass
from envelope.footprint import polygon_to_geojson
from envelope.mesh import MERGE_DECIMALS, LabelledMesh
from envelope.truth import Building, BuildingTruth, BuildingType, FacadeTruth
from envelope.wwr import ClassAreas

HIDDEN_NOISE_M2 = 1e-6
"""A hidden area below this (1 cm x 0.1 mm) is round-off of the polygon operations, not a
surface in front of the facade: the visible area is then the full one exactly."""


@dataclass(frozen=True)
class BuildingLayout:
    """Everything a building is made of before triangulation.

    ``footprint_xy`` is the (n, 2) ground outline (world x/y metres), ``walls`` the facade
    walls, ``other_faces`` ground, roof and attached solids (balconies, chimneys).
    """

    footprint_xy: np.ndarray
    walls: list[WallSpec]
    other_faces: list[PlanarFace]
    floors: int
    height_m: float
    curved_facade_ids: frozenset[int] = frozenset()
    extra: dict[str, Any] = field(default_factory=dict)


def facade_truths(
    walls: list[WallSpec], curved_facade_ids: frozenset[int] = frozenset()
) -> tuple[FacadeTruth, ...]:
    """Truth of every facade (walls grouped by facade id, sorted by id).

    Width is the summed wall length along the facets of a curved facade, and for a planar
    facade the length of the union of its walls' spans along it (a recess's back wall
    adds none); height the highest wall point, normal the length-weighted mean outward normal.
    """
    ids = sorted({w.facade_id for w in walls})
    if ids != list(range(1, len(ids) + 1)):
        raise ValueError(f"facade ids must be 1..n without gaps, got {ids}")
    out = []
    for fid in ids:
        group = [w for w in walls if w.facade_id == fid]
        window = sum(w.opening_area_m2("window") for w in group)
        door = sum(w.opening_area_m2("door") for w in group)
        wall = sum(w.wall_area_m2() for w in group)
        areas = ClassAreas(window, wall, door)
        normal = sum(w.frame.length_m * w.frame.normal for w in group)
        normal = normal / np.linalg.norm(normal)
        out.append(
            FacadeTruth(
                id=fid,
                normal=tuple(round(float(x), 12) + 0.0 for x in normal),
                width_m=_width_m(group),
                height_m=max(w.height_m for w in group),
                window_area_m2=float(window),
                wall_area_m2=float(wall),
                door_area_m2=float(door),
                facade_area_m2=areas.gross_m2,
                wwr=areas.wwr,
                curved=fid in curved_facade_ids,
            )
        )
    return tuple(out)


def _width_m(group: list[WallSpec]) -> float:
    """Summed wall length (curved facade) or the union of parallel walls' spans along them."""
    axis = group[0].frame.u_axis
    if len(group) == 1 or any(not np.allclose(w.frame.u_axis, axis, atol=1e-9) for w in group):
        return float(sum(w.frame.length_m for w in group))
    spans = sorted(sorted((float(np.dot([*w.frame.p0_xy, 0.0], axis)),
                           float(np.dot([*w.frame.p1_xy, 0.0], axis)))) for w in group)
    total, reach = 0.0, -np.inf
    for lo, hi in spans:
        total += max(0.0, hi - max(lo, reach))
        reach = max(reach, hi)
    return total


def facade_outlines_m(walls: list[WallSpec]) -> dict[str, list[list[list[float]]]]:
    """Per facade id (as a string key, for JSON): the world-frame outline of each of its walls.

    Each outline is a list of [x, y, z] corners in metres, counter-clockwise seen from outside;
    a planar facade has one, a faceted curved facade one per facet.
    """
    out: dict[str, list[list[list[float]]]] = {}
    for w in walls:
        corners = np.round(w.frame.points_m(w.outline_uv), MERGE_DECIMALS) + 0.0
        out.setdefault(str(w.facade_id), []).append(corners.tolist())
    return out


def assemble_building(
    *,
    building_id: str,
    building_type: BuildingType,
    seed: int | None,
    floors: int,
    height_m: float,
    footprint_xy: np.ndarray,
    walls: list[WallSpec],
    other_faces: list[PlanarFace],
    curved_facade_ids: frozenset[int] = frozenset(),
    name: str = "",
    extra: dict[str, Any] | None = None,
) -> Building:
    """Triangulate walls (with openings) and the other faces; attach the analytic truth.

    ``footprint_xy`` is the (n, 2) ground outline in world x/y metres.
    """
    if floors < 1:
        raise ValueError(f"a building needs floors >= 1, got {floors}")
    faces = [face for w in walls for face in wall_faces(w)] + list(other_faces)
    mesh = triangulate_faces(faces)
    facades = with_visible_areas(facade_truths(walls, curved_facade_ids), mesh)
    window = sum(f.window_area_m2 for f in facades)
    door = sum(f.door_area_m2 for f in facades)
    wall = sum(f.wall_area_m2 for f in facades)
    areas = ClassAreas(window, wall, door)
    footprint = Polygon(footprint_xy)
    truth = BuildingTruth(
        id=building_id,
        type=building_type,
        floors=int(floors),
        height_m=float(height_m),
        window_area_m2=float(window),
        facade_area_m2=areas.gross_m2,
        wall_area_m2=float(wall),
        door_area_m2=float(door),
        wwr=areas.wwr,
        footprint=polygon_to_geojson(footprint),
        footprint_area_m2=float(footprint.area),
        facades=facades,
        name=name,
        seed=seed,
        extra=dict(extra or {}),
        facade_outlines_m=facade_outlines_m(walls),
    )
    return Building(mesh=mesh, truth=truth)


def with_visible_areas(facades: tuple[FacadeTruth, ...],
                       mesh: LabelledMesh) -> tuple[FacadeTruth, ...]:
    """``facades`` with their areas seen straight on: the full ones less what other surfaces
    of ``mesh`` hide from the front (:mod:`dataset.families.visible_facade`).
    """
    hidden = hidden_facade_areas_m2(mesh)
    out = []
    for f in facades:
        h = hidden.get(f.id, {})
        out.append(replace(
            f,
            visible_window_area_m2=_less(f.window_area_m2, h.get(SemanticClass.WINDOW, 0.0)),
            visible_wall_area_m2=_less(f.wall_area_m2, h.get(SemanticClass.WALL, 0.0)),
            visible_door_area_m2=_less(f.door_area_m2, h.get(SemanticClass.DOOR, 0.0)),
        ))
    return tuple(out)


def _less(area_m2: float, hidden_m2: float) -> float:
    """``area_m2 - hidden_m2``; a hidden area under :data:`HIDDEN_NOISE_M2` is polygon round-off."""
    return float(area_m2) if hidden_m2 < HIDDEN_NOISE_M2 else float(area_m2 - hidden_m2)


def assemble_layout(
    layout: BuildingLayout,
    *,
    building_id: str,
    building_type: BuildingType,
    seed: int | None,
    name: str = "",
) -> Building:
    """:func:`assemble_building` of a :class:`BuildingLayout`."""
    return assemble_building(
        building_id=building_id,
        building_type=building_type,
        seed=seed,
        floors=layout.floors,
        height_m=layout.height_m,
        footprint_xy=layout.footprint_xy,
        walls=layout.walls,
        other_faces=layout.other_faces,
        curved_facade_ids=layout.curved_facade_ids,
        name=name,
        extra=layout.extra,
    )
