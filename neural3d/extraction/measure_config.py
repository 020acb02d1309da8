"""How a semantic mesh is measured: :class:`MeasureConfig` (see
:mod:`neural3d.extraction.measure`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from dataset.rendering.visibility import MIN_ESCAPE_FRACTION, RAY_OFFSET_M


@dataclass(frozen=True)
class MeasureConfig:
    """How facade areas are counted and facades grouped (see the module docstring).

    ``count="projected"`` counts facade triangles by their shadow on the nearest
    facade plane (robust to the wavy walls, recesses and undersides of a neural
    field's mesh); ``count="all"`` sums the classes over every triangle (the
    paper); ``count="grouped"`` only over triangles in a kept facade group.

    Only faces seen from outside count (``visibility_rays_per_sample`` > 0): a
    trained field may close surfaces inside the building (a blob behind the
    windows, the sides of a tunnel at a door), which no facade holds.
    """

    count: Literal["projected", "all", "grouped"] = "projected"
    facade_max_tilt_deg: float = 30.0
    azimuth_bin_deg: float = 1.0
    azimuth_smoothing_deg: float = 3.0
    min_facade_separation_deg: float = 30.0
    plane_gap_m: float = 1.0
    min_facade_area_m2: float = 1.0
    min_facade_area_fraction: float = 0.02
    # a trained wall wanders ~0.2 m; 0.4 m keeps a 5 m radius curve's segments within 2 %
    plane_slab_m: float = 0.4
    plane_max_angle_deg: float = 60.0
    curve_strip_m: float = 1.0  # wider than a window recess, narrow enough to follow a curve
    # facade hidden behind balconies (neural3d.extraction.occluded_facade), "projected" only:
    # grid cell (0 = off) and how far in front of a plane occluders are looked for
    occlusion_cell_m: float = 0.1
    occluder_reach_m: float = 3.0
    # a concave corner the field filled (neural3d.extraction.concave_corners), with occlusion:
    # the longest run of a wall's row continued to the corner line (0 = off)
    corner_max_gap_m: float = 1.5
    # seen from outside (dataset.rendering.visibility): 4 points x this many rays per face;
    # 0 = every face counts
    visibility_rays_per_sample: int = 4
    min_escape_fraction: float = MIN_ESCAPE_FRACTION
    ray_offset_m: float = RAY_OFFSET_M

    def __post_init__(self) -> None:
        if self.count not in ("projected", "all", "grouped"):
            raise ValueError(f"count must be 'projected', 'all' or 'grouped', got {self.count!r}")
        if not 0.0 < self.plane_max_angle_deg < 90.0:
            raise ValueError(f"plane_max_angle_deg must be in (0, 90), got "
                             f"{self.plane_max_angle_deg}")
        if not 0.0 <= self.facade_max_tilt_deg < 90.0:
            raise ValueError(f"facade_max_tilt_deg must be in [0, 90), got "
                             f"{self.facade_max_tilt_deg}")
        if not 0.0 < self.azimuth_bin_deg <= 10.0:
            raise ValueError(f"azimuth_bin_deg must be in (0, 10], got {self.azimuth_bin_deg}")
        if not 0.0 < self.min_facade_separation_deg <= 180.0:
            raise ValueError("min_facade_separation_deg must be in (0, 180], got "
                             f"{self.min_facade_separation_deg}")
        for name in ("azimuth_smoothing_deg", "plane_gap_m", "min_facade_area_m2",
                     "min_facade_area_fraction", "plane_slab_m", "corner_max_gap_m"):
            if getattr(self, name) < 0:
                raise ValueError(f"{name} must be >= 0, got {getattr(self, name)}")
        if self.visibility_rays_per_sample < 0 or not 0 < self.min_escape_fraction <= 1:
            raise ValueError(f"visibility_rays_per_sample must be >= 0 and min_escape_fraction "
                             f"in (0, 1], got {self.visibility_rays_per_sample}, "
                             f"{self.min_escape_fraction}")
        if self.occlusion_cell_m < 0 or not self.occluder_reach_m > self.plane_slab_m:
            raise ValueError(f"occlusion_cell_m must be >= 0 and occluder_reach_m > plane_slab_m, "
                             f"got {self.occlusion_cell_m}, {self.occluder_reach_m}")
        if not self.curve_strip_m > 0:
            raise ValueError(f"curve_strip_m must be > 0, got {self.curve_strip_m}")

    def min_group_area_m2(self, grouped_area_m2: float) -> float:
        """Smallest facade group (or plane) kept, given the grouped facade area in m²."""
        return max(self.min_facade_area_m2, self.min_facade_area_fraction * grouped_area_m2)
