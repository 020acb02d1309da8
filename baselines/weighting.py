"""Building WWR from facade WWRs: the weightings of 2D-S and 2D-SS.

* ``"equal"`` (2D-S): the unweighted mean over facades.
* ``"alpha"`` (2D-SS, as in the paper): sum(WWR_i alpha_i) / sum(alpha_i) with
  alpha_i = L_i / H_i. With equal facade heights (the paper's assumption) this
  is the area-weighted mean; otherwise it is not.
* ``"area"``: sum(WWR_i A_i) / sum(A_i) with A_i = L_i H_i, which equals total
  window area / total facade area.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

Weighting = Literal["equal", "alpha", "area"]
WEIGHTINGS: tuple[str, ...] = ("equal", "alpha", "area")


def facade_weights(
    weighting: Weighting, length_m: np.ndarray | None = None, height_m: np.ndarray | None = None,
    *, count: int | None = None,
) -> np.ndarray:
    """(N,) weights of N facades.

    ``length_m`` and ``height_m`` (N,) are needed for "alpha" and "area";
    "equal" needs only ``count`` (or either array).
    """
    if weighting not in WEIGHTINGS:
        raise ValueError(f"unknown weighting {weighting!r}; expected one of {WEIGHTINGS}")
    if weighting == "equal":
        n = count if count is not None else len(length_m if length_m is not None else height_m)
        return np.ones(n)
    if length_m is None or height_m is None:
        raise ValueError(f"weighting {weighting!r} needs facade lengths and heights")
    L = np.asarray(length_m, dtype=np.float64)
    H = np.asarray(height_m, dtype=np.float64)
    if L.shape != H.shape or L.ndim != 1:
        raise ValueError(f"length_m and height_m must be (N,) alike, got {L.shape} and {H.shape}")
    if not (np.all(L > 0) and np.all(H > 0)):
        raise ValueError("facade lengths and heights must be > 0 m")
    return L / H if weighting == "alpha" else L * H


def weighted_building_wwr(wwr: np.ndarray, weights: np.ndarray) -> float:
    """sum(wwr_i w_i) / sum(w_i) over (N,) facade WWRs and weights.

    Raises
    ------
    ValueError
        If there is no facade, shapes differ, or the weights do not sum to > 0.
    """
    r = np.asarray(wwr, dtype=np.float64)
    w = np.asarray(weights, dtype=np.float64)
    if r.ndim != 1 or r.shape != w.shape or len(r) == 0:
        raise ValueError(f"wwr and weights must be (N,) alike with N >= 1, got {r.shape}, "
                         f"{w.shape}")
    if np.any(w < 0) or w.sum() <= 0:
        raise ValueError("facade weights must be >= 0 and sum to > 0")
    return float(np.sum(r * w) / np.sum(w))
