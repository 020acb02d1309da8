"""Hand-made ground truth and results for the metrics, compare and figures tests.

Every figure here is chosen so the expected errors are easy to work out by hand.
"""

from __future__ import annotations

from pathlib import Path

from shapely.geometry import box

from envelope.footprint import polygon_to_geojson
from envelope.protocols import VIEW_PROTOCOLS
from envelope.results import FacadeEstimate, MethodResult, write_result
from envelope.truth import BuildingTruth, FacadeTruth, write_building

# Two facades: (window, wall, door) m² -> gross 40 and 20 m², both WWR 0.25; total 15 / 60.
FACADES = ((10.0, 30.0, 0.0), (5.0, 13.0, 2.0))
SQUARE = box(0.0, 0.0, 10.0, 10.0)  # 100 m² footprint


def make_truth(scene: str, family: str = "skyscraper") -> BuildingTruth:
    """A two-facade building: WWR 0.25, window 15 m², facade 60 m², a 10 m square footprint."""
    facades = tuple(
        FacadeTruth(
            id=i + 1, normal=(1.0, 0.0, 0.0) if i == 0 else (0.0, 1.0, 0.0),
            width_m=10.0, height_m=(win + wall + door) / 10.0, window_area_m2=win,
            wall_area_m2=wall, door_area_m2=door, facade_area_m2=win + wall + door,
            wwr=win / (win + wall + door),
        )
        for i, (win, wall, door) in enumerate(FACADES)
    )
    return BuildingTruth(
        id=scene, type=family, floors=2, height_m=6.0, window_area_m2=15.0,
        facade_area_m2=60.0, wall_area_m2=43.0, door_area_m2=2.0, wwr=0.25,
        footprint=polygon_to_geojson(SQUARE), footprint_area_m2=100.0, facades=facades,
    )


def make_result(
    scene: str, method: str, protocol: str, wwr: float | None, *,
    window_m2: float | None = None, facade_m2: float | None = None,
    footprint_shift_m: float | None = None, facade_wwrs: tuple[float, ...] = (),
) -> MethodResult:
    """A result with the given figures; a footprint is the truth's square moved along x."""
    footprint = None
    if footprint_shift_m is not None:
        moved = box(footprint_shift_m, 0.0, 10.0 + footprint_shift_m, 10.0)
        footprint = polygon_to_geojson(moved)
    facades = tuple(
        FacadeEstimate(id=i + 1, wwr=w, window_area_m2=w * 40.0, facade_area_m2=40.0)
        for i, w in enumerate(facade_wwrs)
    )
    return MethodResult(
        scene=scene, method=method, protocol=protocol, wwr=wwr, window_area_m2=window_m2,
        facade_area_m2=facade_m2, facades=facades, footprint=footprint,
        config={"hand_made": True}, code_version="test", wall_time_s=1.0,
        facade_identity="truth_id" if protocol in VIEW_PROTOCOLS else "geometry",
    )


def make_benchmark(root: Path) -> tuple[Path, Path]:
    """Scenes ``sky_a``, ``sky_b`` (skyscraper) and ``ell_c`` (l_shaped) and their results.

    2D-S ideal: WWR APE 20, 10 (skyscraper: 15 ± 5) and 0 (l_shaped); window APE
    20, 0 and 0; facade APE 0 everywhere. 2D-SS ideal: sky_a 40 %, sky_b 0 %,
    ell_c a corrupt file. neural3d train: footprint IoU 1/3 and 1 (skyscraper:
    2/3 ± 1/3), ell_c has no result file.
    Returns (data folder, results folder).
    """
    data, results = root / "data", root / "results"
    for scene, family in (("sky_a", "skyscraper"), ("sky_b", "skyscraper"),
                          ("ell_c", "l_shaped")):
        write_building(data / scene / "building.json", make_truth(scene, family))
    for r in (
        make_result("sky_a", "2D-S", "ideal", 0.30, window_m2=18.0, facade_m2=60.0,
                    facade_wwrs=(0.3, 0.25)),
        make_result("sky_b", "2D-S", "ideal", 0.275, window_m2=15.0, facade_m2=60.0),
        make_result("ell_c", "2D-S", "ideal", 0.25, window_m2=15.0, facade_m2=60.0),
        make_result("sky_a", "2D-SS", "ideal", 0.35, window_m2=15.0, facade_m2=60.0),
        make_result("sky_b", "2D-SS", "ideal", 0.25, window_m2=15.0, facade_m2=60.0),
        make_result("sky_a", "neural3d", "train", 0.25, window_m2=15.0, facade_m2=60.0,
                    footprint_shift_m=5.0),
        make_result("sky_b", "neural3d", "train", 0.25, window_m2=15.0, facade_m2=60.0,
                    footprint_shift_m=0.0),
    ):
        write_result(results, r)
    (results / "ell_c__2D-SS__ideal.json").write_text('{"scene": "ell_c", "wwr": ')
    return data, results
