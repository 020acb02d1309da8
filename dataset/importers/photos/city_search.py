"""The coarse global search of a city-model fit: no initial guess from the user
(docs/importing.md, section 9).

Seen from above, the photos' points on facades lie on the model's wall lines. For every
heading on a grid (:attr:`SearchConfig.heading_step_deg`) and every scale on a log grid
(:attr:`SearchConfig.scale_step`, a factor of :attr:`SearchConfig.scale_range` either side
of :func:`scale_guess`; scales that spread the points over :data:`MAX_SPREAD` times the
model's extent are left out), the levelled points' ground projection is binned on a grid
(:attr:`SearchConfig.cells_across` cells across the model's walls, at most 1 m) and
correlated (FFT) with a map of the walls that is 1 on a wall and falls to 0
:attr:`SearchConfig.reach_cells` cells away (a chamfer score from the distance
transform): the correlation's peak is the best horizontal shift for that heading and
scale, its value the number of points it brings near a wall. The best few distinct peaks
(:func:`coarse_candidates`) go to the refinement (:mod:`dataset.importers.photos.city_icp`).
The height comes from the ground: the points' ground at the building's lowest ground
point, z = 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import fft
from scipy.ndimage import distance_transform_edt

from dataset.importers.photos.city_icp import PlacedSimilarity, SurfaceSamples

CLIP_PERCENTILES = (5.0, 95.0)
"""Points outside the box between these percentiles take no part in the coarse search."""
MAX_SPREAD = 1.5
"""Scales at which those points' box would be wider than this many times the model walls'
box are not tried: the model is assumed to hold what the photos see (the building and the
neighbours round it), so their points spread no wider than it, with a margin."""


@dataclass(frozen=True)
class SearchConfig:
    """The coarse search's grids; lengths in metres, angles in degrees.

    ``cells_across``: grid cells across the longer side of the walls' box (the cell is
    that side over this, at most ``max_cell_m``: coarser cells cannot tell a street front
    from the same points shrunk into a block's walls); ``scale_range``: the scales tried
    run from ``guess / scale_range`` to ``guess * scale_range`` (:func:`scale_guess`);
    ``scale_step``: the log step between them (0.12: 12 %); ``candidates``: distinct peaks
    kept; distinct means headings ``distinct_heading_deg`` apart, scales a factor
    ``exp(distinct_log_scale)`` apart or the points' middle landing ``distinct_shift_m``
    apart."""

    heading_step_deg: float = 6.0
    scale_step: float = 0.12
    scale_range: float = 2.5
    cells_across: int = 48
    max_cell_m: float = 1.0
    reach_cells: int = 2
    candidates: int = 6
    distinct_heading_deg: float = 10.0
    distinct_log_scale: float = 0.2
    distinct_shift_m: float = 4.0

    def __post_init__(self) -> None:
        if not (0 < self.heading_step_deg <= 30 and 0 < self.scale_step <= 0.5
                and self.scale_range >= 1 and self.cells_across >= 8 and self.max_cell_m > 0
                and self.reach_cells >= 1
                and self.candidates >= 2):
            raise ValueError(f"search config out of range: {self}")


@dataclass(frozen=True)
class Candidate:
    """A peak of the coarse search: the share of the points it brings near a wall, and the
    similarity (the height from the ground)."""

    score: float
    similarity: PlacedSimilarity


def scale_guess(ground_z: float, top_z: float, building_height_m: float) -> float:
    """The scale that makes the levelled points' height span, from their ground ``ground_z``
    to their top ``top_z``, the building's height (m): the photos are assumed to see the
    building from its foot to about its top, within :attr:`SearchConfig.scale_range`
    (taller neighbours, trees, or photos that miss the top widen the gap)."""
    return building_height_m / max(top_z - ground_z, 1e-12)


def coarse_candidates(points: np.ndarray, ground_z: float, top_z: float,
                      samples: SurfaceSamples, building_height_m: float,
                      config: SearchConfig = SearchConfig()) -> list[Candidate]:
    """The best distinct peaks of the search (module docstring), best first, then the
    best peaks at the best one's scale and its heading turned a quarter, a half and three
    quarters (a building's symmetric alternatives, always tried so that a fit they match as
    well is found ambiguous), for (N, 3) levelled points whose ground and top lie at
    heights ``ground_z`` and ``top_z`` (levelled frame), fitted to a model whose building
    is ``building_height_m`` tall."""
    walls = samples.points_m[samples.vertical, :2]
    if len(walls) == 0:
        raise ValueError("the city model has no wall to fit the photos to")
    points = np.asarray(points, dtype=np.float64)
    guess = scale_guess(ground_z, top_z, building_height_m)
    xy = points[:, :2]
    lo, hi = np.percentile(xy, CLIP_PERCENTILES, axis=0)
    xy = xy[np.all((xy >= lo) & (xy <= hi), axis=1)]
    steps = int(np.ceil(np.log(config.scale_range) / config.scale_step))
    scales = guess * np.exp(config.scale_step * np.arange(-steps, steps + 1))
    headings = np.radians(np.arange(0.0, 360.0, config.heading_step_deg))
    cell = min(float(np.ptp(walls, axis=0).max()) / config.cells_across, config.max_cell_m)
    score_map, origin = _wall_map(walls, cell, config.reach_cells)
    centred = xy - xy.mean(axis=0)
    span = float(np.linalg.norm(np.ptp(centred, axis=0)))
    scales = scales[scales * span <= MAX_SPREAD * float(np.linalg.norm(np.ptp(walls, axis=0)))]
    if len(scales) == 0:
        raise ValueError(
            f"--city-model: at the least scale tried ({guess / config.scale_range:.3g}, from "
            f"the building's height) the photos' points spread over {MAX_SPREAD:g} times the "
            f"model's extent or more: the model must hold what the photos see (give the "
            f"folder of the city model's files, for the neighbours), or the photos do not "
            f"show the building's foot and top")
    size = [fft.next_fast_len(n + int(np.ceil(scales[-1] * span / cell)) + 2, True)
            for n in score_map.shape]
    map_f = fft.rfft2(score_map, size)
    peaks = []
    for heading in headings:
        c, s = np.cos(heading), np.sin(heading)
        turned = centred @ np.array([[c, -s], [s, c]]).T
        for scale in scales:
            for score, shift in _best_shifts(scale * turned, map_f, score_map.shape, size,
                                             origin, cell, config.distinct_shift_m):
                peaks.append((score / len(xy), heading, scale, shift))
    middle = xy.mean(axis=0)
    middle_3d = np.array([*middle, ground_z])

    def candidate(peak: tuple) -> Candidate:
        score, heading, scale, shift = peak
        c, s = np.cos(heading), np.sin(heading)
        shift_xy = shift - scale * np.array([[c, -s], [s, c]]) @ middle
        return Candidate(score, PlacedSimilarity(float(scale), float(heading),
                                                 np.array([*shift_xy, -scale * ground_z])))

    kept: list[Candidate] = []
    for peak in sorted(peaks, key=lambda p: -p[0]):
        c = candidate(peak)
        if all(distinct(c.similarity, k.similarity, middle_3d, config) for k in kept):
            kept.append(c)
            if len(kept) == config.candidates:
                break
    best = kept[0].similarity
    for quarter in (1, 2, 3):  # the best one's symmetric alternatives, at its scale
        heading = (best.heading_rad + quarter * np.pi / 2) % (2 * np.pi)
        half_step = np.radians(config.heading_step_deg) / 2
        same = [p for p in peaks if p[2] == best.scale
                and abs((p[1] - heading + np.pi) % (2 * np.pi) - np.pi) <= half_step]
        if same:
            kept.append(candidate(max(same, key=lambda p: p[0])))
    return kept


def _wall_map(walls_xy: np.ndarray, cell_m: float, reach_cells: int
              ) -> tuple[np.ndarray, np.ndarray]:
    """The chamfer score map of the walls on cells of ``cell_m`` ((H, W): 1 on a wall, 0
    from ``reach_cells + 1`` cells away) and the (2,) x, y of its first cell's corner."""
    origin = walls_xy.min(axis=0) - (reach_cells + 1) * cell_m
    index = np.floor((walls_xy - origin) / cell_m).astype(np.int64)
    shape = tuple(index.max(axis=0) + reach_cells + 2)
    occupied = np.zeros(shape, dtype=bool)
    occupied[index[:, 0], index[:, 1]] = True
    distance = distance_transform_edt(~occupied)
    return np.clip(1.0 - distance / (reach_cells + 1), 0.0, 1.0), origin


def _best_shifts(xy: np.ndarray, map_f: np.ndarray, map_shape: tuple[int, int],
                 size: list[int], origin: np.ndarray, cell_m: float, apart_m: float
                 ) -> list[tuple[float, np.ndarray]]:
    """The correlation's peak and the best peak ``apart_m`` away from it: (score, (2,)
    shift in metres to add to ``xy``) each."""
    low = xy.min(axis=0)
    index = np.floor((xy - low) / cell_m).astype(np.int64)
    shape = index.max(axis=0) + 1
    counts = np.bincount(index[:, 0] * shape[1] + index[:, 1],
                         minlength=int(shape[0] * shape[1])).reshape(shape)
    corr = fft.irfft2(map_f * fft.rfft2(counts[::-1, ::-1], size), size)
    corr = corr[:map_shape[0] + shape[0] - 1, :map_shape[1] + shape[1] - 1]
    out = []
    for _ in range(2):
        m = np.unravel_index(int(np.argmax(corr)), corr.shape)
        k = np.array(m) - (shape - 1)
        out.append((float(corr[m]), origin + k * cell_m - low))
        reach = int(np.ceil(apart_m / cell_m))
        corr[max(0, m[0] - reach):m[0] + reach + 1, max(0, m[1] - reach):m[1] + reach + 1] = 0
    return out


def distinct(a: PlacedSimilarity, b: PlacedSimilarity, middle: np.ndarray,
             config: SearchConfig) -> bool:
    """Whether two similarities differ: in heading, in scale, or in where they take the
    (3,) levelled point ``middle`` (the points' middle) (:class:`SearchConfig`)."""
    turn = (a.heading_rad - b.heading_rad + np.pi) % (2 * np.pi) - np.pi
    land = float(np.linalg.norm(a.apply(middle[None]) - b.apply(middle[None])))
    return bool(abs(np.degrees(turn)) > config.distinct_heading_deg
                or abs(np.log(a.scale / b.scale)) > config.distinct_log_scale
                or land > config.distinct_shift_m)
