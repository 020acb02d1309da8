"""From per-view measurements to facade estimates and the building's result file.

Multi views of one facade are combined by the mean (the paper's choice) or the
median of each measured quantity. A facade with no usable view is reported as
missing with the reasons its views were skipped; it is counted in the result's
warnings and left out of the building's sums and weights.
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np

from baselines.weighting import Weighting, facade_weights, weighted_building_wwr
from envelope.results import FacadeEstimate, MethodResult, code_version

Combine = Literal["mean", "median"]
COMBINES: tuple[str, ...] = ("mean", "median")


def combine_values(values: list[float | None], how: Combine) -> float | None:
    """Mean or median of the values that are not ``None``; ``None`` if there are none."""
    if how not in COMBINES:
        raise ValueError(f"unknown combination {how!r}; expected one of {COMBINES}")
    v = np.array([x for x in values if x is not None], dtype=np.float64)
    if len(v) == 0:
        return None
    return float(np.mean(v) if how == "mean" else np.median(v))


def missing_facade(facade_id: int, reasons: list[str]) -> FacadeEstimate:
    """The estimate of a facade that had no usable view, with the (distinct) reasons."""
    distinct = list(dict.fromkeys(reasons)) or ["no view of this facade"]
    return FacadeEstimate(id=facade_id, wwr=None, missing=True,
                          reason="no usable view: " + "; ".join(distinct))


def building_result(
    *,
    scene: str,
    method: str,
    protocol: str,
    facades: list[FacadeEstimate],
    weighting: Weighting,
    config: dict[str, Any],
    wall_time_s: float,
    warnings: list[str],
) -> MethodResult:
    """The building's result: weighted WWR over the facades present, summed areas.

    Raises
    ------
    ValueError
        If no facade has a usable view (the message lists why).
    """
    present = [f for f in facades if not f.missing]
    warnings = list(warnings)
    if not present:
        reasons = ("; ".join(f"facade {f.id}: {f.reason}" for f in facades)
                   or "; ".join(warnings) or "no facade views")
        raise ValueError(f"{scene} ({method}, {protocol}): nothing left to measure: {reasons}")
    missing = [f.id for f in facades if f.missing]
    if missing:
        warnings.append(f"{len(missing)} of {len(facades)} facades missing (ids "
                        f"{', '.join(map(str, missing))}); building figures cover the rest")
    lengths = heights = None
    if weighting != "equal":
        lengths = np.array([f.width_m for f in present])
        heights = np.array([f.height_m for f in present])
    weights = facade_weights(weighting, lengths, heights, count=len(present))
    wwr = weighted_building_wwr(np.array([f.wwr for f in present]), weights)
    window = _sum_or_none([f.window_area_m2 for f in present])
    facade = _sum_or_none([f.facade_area_m2 for f in present])
    if window is None or facade is None:
        warnings.append("building areas unavailable: some facades have no area scale (depth)")
    return MethodResult(
        scene=scene, method=method, protocol=protocol, wwr=wwr,
        window_area_m2=window, facade_area_m2=facade,
        facades=tuple(sorted(facades, key=lambda f: f.id)),
        config=config, code_version=code_version(), wall_time_s=wall_time_s,
        warnings=tuple(warnings),
    )


def _sum_or_none(values: list[float | None]) -> float | None:
    if any(v is None for v in values):
        return None
    return float(sum(values))
