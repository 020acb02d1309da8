"""A box building with known openings, turned 30 degrees, with a stated north (tests/test_export*).

The plan is 10 m (local x) by 6 m (local y), 9 m high. In the world its walls
face 30 degrees clockwise of their plan directions, and its ``north_deg`` of 20
turns them 20 more from true north: the plan's south wall faces 230 (W), east
140 (S), north 50 (E), west 320 (N). Without the stated north they would bin
S, E, N, W, so every bin tests that north was applied.

Openings by hand: plan south 90 m² gross, 12 m² window (WWR 2/15); plan east
54 m², no window (WWR 0); plan north 90 m², 27 m² window and a 2.1 m² door
(WWR 0.3); plan west 54 m², 10.8 m² window (WWR 0.2).
"""

from __future__ import annotations

import math

import numpy as np
from shapely.geometry import Polygon

from envelope.footprint import polygon_to_geojson
from envelope.results import FacadeEstimate, MethodResult
from envelope.truth import BuildingTruth, FacadeTruth

TURN_DEG = 30.0  # the walls' turn in the world frame, clockwise seen from above
NORTH_DEG = 20.0  # the stated north: true north to world +y, clockwise
HEIGHT_M = 9.0
PLAN = ((0.0, 0.0), (10.0, 0.0), (10.0, 6.0), (0.0, 6.0))  # counter-clockwise
# facade id -> (plan edge start index, window m², door m²); edge i runs PLAN[i] -> PLAN[i+1]
OPENINGS = {1: (0, 12.0, 0.0), 2: (1, 0.0, 0.0), 3: (2, 27.0, 2.1), 4: (3, 10.8, 0.0)}
# What every export must say, per true-north bin: (gross m², window m², WWR)
EXPECTED = {"W": (90.0, 12.0, 12.0 / 90.0), "S": (54.0, 0.0, 0.0),
            "E": (90.0, 27.0, 0.3), "N": (54.0, 10.8, 0.2)}
AZIMUTH_DEG = {1: 230.0, 2: 140.0, 3: 50.0, 4: 320.0}


def turned_xy(x: float, y: float) -> tuple[float, float]:
    """Plan x/y turned clockwise by TURN_DEG (azimuths grow by TURN_DEG)."""
    t = math.radians(TURN_DEG)
    return (x * math.cos(t) + y * math.sin(t), -x * math.sin(t) + y * math.cos(t))


def box_truth(scene: str = "box") -> BuildingTruth:
    """The box's exact truth: facades, outlines (counter-clockwise from outside), footprint."""
    corners = [turned_xy(x, y) for x, y in PLAN]
    facades, outlines = [], {}
    for fid, (edge, window, door) in OPENINGS.items():
        (x0, y0), (x1, y1) = corners[edge], corners[(edge + 1) % 4]
        width = math.hypot(x1 - x0, y1 - y0)
        gross = width * HEIGHT_M
        normal = (float((y1 - y0) / width), float(-(x1 - x0) / width), 0.0)
        facades.append(FacadeTruth(
            id=fid, normal=normal, width_m=width, height_m=HEIGHT_M, window_area_m2=window,
            wall_area_m2=gross - window - door, door_area_m2=door, facade_area_m2=gross,
            wwr=window / gross))
        outlines[fid] = [[(x0, y0, 0.0), (x1, y1, 0.0), (x1, y1, HEIGHT_M),
                          (x0, y0, HEIGHT_M)]]
    gross = sum(f.facade_area_m2 for f in facades)
    window = sum(f.window_area_m2 for f in facades)
    door = sum(f.door_area_m2 for f in facades)
    footprint = Polygon(corners)
    return BuildingTruth(
        id=scene, type="skyscraper", floors=3, height_m=HEIGHT_M, window_area_m2=window,
        facade_area_m2=gross, wall_area_m2=gross - window - door, door_area_m2=door,
        wwr=window / gross, footprint=polygon_to_geojson(footprint),
        footprint_area_m2=footprint.area, facades=tuple(facades), facade_outlines_m=outlines,
        north_deg=NORTH_DEG, north_source="user")


def ideal_result(scene: str = "box") -> MethodResult:
    """A 2D-SS-like result on the truth's facade ids: facade 1 WWR 0.15, facade 2 WWR 0 (stays
    0), facade 3 WWR 0.25, facade 4 missing."""
    facades = (
        FacadeEstimate(id=1, wwr=0.15, window_area_m2=13.5, facade_area_m2=90.0),
        FacadeEstimate(id=2, wwr=0.0, window_area_m2=0.0, facade_area_m2=54.0),
        FacadeEstimate(id=3, wwr=0.25, window_area_m2=22.5, facade_area_m2=90.0),
        FacadeEstimate(id=4, wwr=None, missing=True, reason="no usable view"),
    )
    return MethodResult(scene=scene, method="2D-SS", protocol="ideal", wwr=36.0 / 234.0,
                        window_area_m2=36.0, facade_area_m2=234.0, facades=facades,
                        facade_identity="truth_id")


def located_result(scene: str = "box") -> MethodResult:
    """A neural3d-like result with its own ids, normals and centres: its facade 7 is the
    truth's 3 (WWR 0.28), its facade 8 the truth's 2 (WWR 0), nothing on 1 and 4."""
    truth = box_truth(scene)

    def centre(fid: int) -> tuple[float, float, float]:
        return tuple(float(c) for c in np.mean(truth.facade_outlines_m[fid][0], axis=0))

    facades = (
        FacadeEstimate(id=7, wwr=0.28, window_area_m2=0.28 * 88.0, facade_area_m2=88.0,
                       normal=truth.facade(3).normal, centre_m=centre(3)),
        FacadeEstimate(id=8, wwr=0.0, window_area_m2=0.0, facade_area_m2=55.0,
                       normal=truth.facade(2).normal, centre_m=centre(2)),
    )
    return MethodResult(scene=scene, method="neural3d", protocol="train",
                        wwr=0.28 * 88.0 / 143.0, window_area_m2=0.28 * 88.0,
                        facade_area_m2=143.0, facades=facades, facade_identity="geometry")
