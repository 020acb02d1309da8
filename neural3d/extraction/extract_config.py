"""What turns a trained field into measurements: :class:`ExtractConfig` and its footprint planes.

Kept apart from :mod:`neural3d.extract` (which needs torch) so that a
comparison can state and check the extraction settings without loading a
field (``metrics.run.methods``).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace

import numpy as np

from neural3d.extraction.measure_config import MeasureConfig, MeasureStages
from neural3d.field.chunks import DEFAULT_CHUNK_POINTS

GROUND_FLOOR_HEIGHTS_M = (1.0, 1.25, 1.5, 1.75, 2.0, 2.25, 2.5)
"""Footprint planes below the lowest first floor (2.7 m): the ground floor's outline."""


@dataclass(frozen=True)
class ExtractConfig:
    """Everything that turns a trained field into measurements (the one source of defaults).

    ``resolution`` is the number of marching-cubes samples along the scene box's
    longest side; ``chunk_points`` the most points one call of the field takes
    (:mod:`neural3d.field.chunks`). The footprint is the zero contour of the SDF averaged
    over the planes ``footprint_heights_m`` above the ground (z = 0): above the least
    constrained band of a trained field (no camera sees the base from below and the scene
    box is cut at z = 0); the default planes (1-4 m) reach into a second storey, so an
    overhang above 2.7 m can enter the outline; :data:`GROUND_FLOOR_HEIGHTS_M` stays below
    any first floor (the ground floor's outline, for buildings whose upper floors, bays or
    balconies overhang; it cuts the ground floor's window reveals, which costs procedural
    buildings without overhangs about 0.003 IoU). The widest outline (every storey's section,
    :func:`neural3d.extraction.footprint.widest_outline_from_sdf`) takes planes
    ``footprint_widest_step_m`` apart from the lowest footprint plane to the box top.
    Planes above ``footprint_max_height_fraction`` of the box's top are left
    out (a low building), keeping at least the lowest. Its grid spacing
    ``footprint_cell_m`` is, when None, half the mesh's voxel, so the footprint
    is as fine as the mesh and costs (2 x resolution)² queries per plane.
    ``roofed_hole_fill`` and ``straight_walls`` switch the footprint's last two stages
    (:func:`neural3d.extraction.footprint.fill_roofed_holes`, then
    :func:`neural3d.extraction.straight_walls.straighten_footprint` with
    ``footprint_wall_tolerance_m`` and ``footprint_min_wall_m``); ``measure.stages`` the
    mesh measurement's.
    """

    resolution: int = 256
    chunk_points: int = DEFAULT_CHUNK_POINTS
    min_component_area_fraction: float = 0.01  # floaters of a neural SDF
    # one slice: L-shape IoU 0.82 at 0.2 m, 0.93 at 0.5 m, 0.97 at 1 m; averaging 1-4 m: +0.01.
    # GROUND_FLOOR_HEIGHTS_M (below any first floor) lost on the approval preset (IoU 0.990 ->
    # 0.987, docs/decisions.md 2026-11-29): not the default until a tuning set with overhangs
    footprint_heights_m: tuple[float, ...] = (1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0)
    footprint_widest_step_m: float = 0.5
    footprint_max_height_fraction: float = 0.5
    footprint_cell_m: float | None = None
    footprint_min_area_m2: float = 1.0
    roofed_hole_fill: bool = True
    # chosen on the ten paper tuning buildings (mean IoU 0.9805 -> 0.9843, none lower by
    # more than 0.0015; docs/decisions.md, 2026-11-27 "straight walls")
    straight_walls: bool = True
    footprint_wall_tolerance_m: float = 0.15
    footprint_min_wall_m: float = 1.0
    measure: MeasureConfig = field(default_factory=MeasureConfig)

    def __post_init__(self) -> None:
        if self.resolution < 8:
            raise ValueError(f"resolution must be >= 8, got {self.resolution}")
        if self.chunk_points < 1:
            raise ValueError(f"chunk_points must be >= 1, got {self.chunk_points}")
        if not self.footprint_heights_m or min(self.footprint_heights_m) < 0:
            raise ValueError("footprint_heights_m must hold at least one height >= 0 m, got "
                             f"{self.footprint_heights_m}")
        if not (self.footprint_wall_tolerance_m > 0 and self.footprint_min_wall_m > 0):
            raise ValueError("footprint_wall_tolerance_m and footprint_min_wall_m must be > 0, "
                             f"got {self.footprint_wall_tolerance_m}, {self.footprint_min_wall_m}")
        if not self.footprint_widest_step_m > 0:
            raise ValueError(f"footprint_widest_step_m must be > 0, got "
                             f"{self.footprint_widest_step_m}")
        if not 0 < self.footprint_max_height_fraction <= 1:
            raise ValueError("footprint_max_height_fraction must be in (0, 1], got "
                             f"{self.footprint_max_height_fraction}")


def footprint_heights_m(box_max_m: np.ndarray, config: ExtractConfig) -> tuple[float, ...]:
    """The configured footprint planes below ``footprint_max_height_fraction`` of the box top.

    At least the lowest configured plane is kept.
    """
    heights = sorted(config.footprint_heights_m)
    top_m = config.footprint_max_height_fraction * float(np.asarray(box_max_m)[2])
    return tuple(h for h in heights if h <= top_m) or (heights[0],)


def footprint_cell_m(box_min_m: np.ndarray, box_max_m: np.ndarray, config: ExtractConfig) -> float:
    """Footprint grid spacing in m: ``config.footprint_cell_m``, or half the mesh voxel if None."""
    if config.footprint_cell_m is not None:
        return config.footprint_cell_m
    longest_m = float(np.max(np.asarray(box_max_m) - np.asarray(box_min_m)))
    return 0.5 * longest_m / (config.resolution - 1)


# Every stage with a switch, in the order it runs: the mesh measurement's, then the footprint's.
FOOTPRINT_STAGES = ("roofed_hole_fill", "straight_walls")
STAGES = (*(f.name for f in fields(MeasureStages)), *FOOTPRINT_STAGES)


def without_stages(config: ExtractConfig, *stages: str) -> ExtractConfig:
    """``config`` with these stages (names from :data:`STAGES`) off, and every measurement
    stage that needs one of them (:meth:`MeasureStages.without`).

    Raises
    ------
    ValueError
        If a name is not a stage.
    """
    unknown = sorted(set(stages) - set(STAGES))
    if unknown:
        raise ValueError(f"unknown stage(s) {unknown}; stages: {', '.join(STAGES)}")
    mesh_stages = [s for s in stages if s not in FOOTPRINT_STAGES]
    measure = replace(config.measure, stages=config.measure.stages.without(*mesh_stages))
    return replace(config, measure=measure,
                   **{s: getattr(config, s) and s not in stages for s in FOOTPRINT_STAGES})
