"""How a semantic mesh is measured: which stages run (:class:`MeasureStages`) and their
settings (:class:`MeasureConfig`); the stages are :mod:`neural3d.extraction.measure_stages`."""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace

from envelope.geometry.visibility import MIN_ESCAPE_FRACTION, RAY_OFFSET_M

# stage -> the stage whose output it reads (a stage runs only with the one it needs)
STAGE_NEEDS = {
    "plane_projection": "grouping",
    "plane_probe": "plane_projection",
    "front_seen_readd": "plane_probe",
    "occluded_fill": "plane_probe",
    "concave_corner_fill": "plane_probe",
}


@dataclass(frozen=True)
class MeasureStages:
    """One switch per stage of :func:`neural3d.extraction.measure.measure_semantic_mesh`, in
    the order they run; each stage's assumptions are in
    :mod:`neural3d.extraction.measure_stages`. All on is neural3d's measurement; all off
    is the paper's count (every triangle's classes by its vertices' labels)."""

    probability_split: bool = True
    visibility_cull: bool = True
    grouping: bool = True
    plane_projection: bool = True
    plane_probe: bool = True
    front_seen_readd: bool = True
    occluded_fill: bool = True
    concave_corner_fill: bool = True

    def __post_init__(self) -> None:
        for stage, needed in STAGE_NEEDS.items():
            if getattr(self, stage) and not getattr(self, needed):
                raise ValueError(f"stage {stage} needs stage {needed}: switch {needed} on or "
                                 f"{stage} off")

    def without(self, *stages: str) -> MeasureStages:
        """These stages off, and every stage that needs one of them.

        Raises
        ------
        ValueError
            If a name is not a stage (the names are this class's fields).
        """
        names = {f.name for f in fields(self)}
        unknown = sorted(set(stages) - names)
        if unknown:
            raise ValueError(f"unknown measurement stage(s) {unknown}; stages: "
                             f"{', '.join(f.name for f in fields(self))}")
        off = set(stages)
        while True:
            more = {s for s, needed in STAGE_NEEDS.items() if needed in off} - off
            if not more:
                return replace(self, **{s: False for s in off})
            off |= more


@dataclass(frozen=True)
class MeasureConfig:
    """Which stages run and the settings each reads (grouped below by stage).

    The assumptions behind each setting and where it biases are documented with
    its stage in :mod:`neural3d.extraction.measure_stages`.
    """

    stages: MeasureStages = field(default_factory=MeasureStages)
    # visibility_cull (envelope.geometry.visibility): 4 points x this many rays per face
    visibility_rays_per_sample: int = 4
    min_escape_fraction: float = MIN_ESCAPE_FRACTION
    ray_offset_m: float = RAY_OFFSET_M
    # grouping (neural3d.extraction.facade_groups)
    facade_max_tilt_deg: float = 30.0
    azimuth_bin_deg: float = 1.0
    azimuth_smoothing_deg: float = 3.0
    min_facade_separation_deg: float = 30.0
    # parallel planes: offsets more than plane_gap_m apart (deeper than the generator's
    # deepest reveal, 0.5 m, so a window stays with its wall); pieces of one plane: more
    # than plane_extent_gap_m apart along it (docs/decisions.md, 2026-11-29)
    plane_gap_m: float = 0.5
    plane_extent_gap_m: float = 1.0
    min_facade_area_m2: float = 1.0
    min_facade_area_fraction: float = 0.02
    # plane_projection (neural3d.extraction.facade_planes); plane_slab_m and
    # plane_max_angle_deg also decide what the plane probe meets.
    # A trained wall wanders ~0.2 m; 0.4 m keeps a 5 m radius curve's segments within 2 %.
    plane_slab_m: float = 0.4
    plane_max_angle_deg: float = 60.0
    curve_strip_m: float = 1.0  # wider than a window recess, narrow enough to follow a curve
    # plane_probe, occluded_fill, concave_corner_fill (neural3d.extraction.occluded_facade,
    # neural3d.extraction.concave_corners): the probe grid's cell, how far in front of a
    # plane occluders are looked for, the longest run continued to a concave corner
    occlusion_cell_m: float = 0.1
    occluder_reach_m: float = 3.0
    corner_max_gap_m: float = 1.5

    def __post_init__(self) -> None:
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
        for name in ("azimuth_smoothing_deg", "plane_gap_m", "plane_extent_gap_m",
                     "min_facade_area_m2",
                     "min_facade_area_fraction", "plane_slab_m"):
            if getattr(self, name) < 0:
                raise ValueError(f"{name} must be >= 0, got {getattr(self, name)}")
        if self.visibility_rays_per_sample < 1 or not 0 < self.min_escape_fraction <= 1:
            raise ValueError(f"visibility_rays_per_sample must be >= 1 and min_escape_fraction "
                             f"in (0, 1], got {self.visibility_rays_per_sample}, "
                             f"{self.min_escape_fraction}")
        if self.occlusion_cell_m <= 0 or not self.occluder_reach_m > self.plane_slab_m:
            raise ValueError(f"occlusion_cell_m must be > 0 and occluder_reach_m > plane_slab_m, "
                             f"got {self.occlusion_cell_m}, {self.occluder_reach_m}")
        if not self.corner_max_gap_m > 0:
            raise ValueError(f"corner_max_gap_m must be > 0, got {self.corner_max_gap_m}")
        if not self.curve_strip_m > 0:
            raise ValueError(f"curve_strip_m must be > 0, got {self.curve_strip_m}")

    def min_group_area_m2(self, grouped_area_m2: float) -> float:
        """Smallest facade group (or plane) kept, given the grouped facade area in m²."""
        return max(self.min_facade_area_m2, self.min_facade_area_fraction * grouped_area_m2)
