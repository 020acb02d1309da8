"""How CityGML buildings become benchmark buildings: :class:`CityGmlConfig`, one place for the
CityGML importer's tolerances (:mod:`dataset.importers.citygml.convert`)."""

from __future__ import annotations

from dataclasses import dataclass

from dataset.importers.import_config import ImportConfig

_MESH = ImportConfig()
_SHARED = ("max_tilt_deg", "angle_tolerance_deg", "offset_tolerance_m", "gap_tolerance_m",
           "min_facade_width_m", "floor_height_m")


@dataclass(frozen=True)
class CityGmlConfig:
    """Tolerances of the CityGML importer; lengths in metres, angles in degrees.

    The facade-grouping tolerances are the mesh importer's (:class:`ImportConfig`), so a
    facade means the same thing whichever way a building came in.
    """

    recentre: bool = True
    """Move each building so that its ground surface's x/y bounding-box centre is at the
    origin and its lowest ground-surface point at z = 0; the offset and the CRS go into the
    truth's ``extra`` so results map back to the file's coordinates."""
    max_tilt_deg: float = _MESH.max_tilt_deg
    """Wall polygons tilted further than this from upright belong to no facade."""
    angle_tolerance_deg: float = _MESH.angle_tolerance_deg
    """Wall and opening polygons within this angle of a facade's direction join it."""
    offset_tolerance_m: float = _MESH.offset_tolerance_m
    """Parallel planes closer than this are one facade (glass set back in its opening)."""
    gap_tolerance_m: float = _MESH.gap_tolerance_m
    """Coplanar pieces further apart than this along the wall are two facades."""
    min_facade_width_m: float = _MESH.min_facade_width_m
    """Narrower groups (reveals, pilaster sides) belong to no facade."""
    max_opening_depth_m: float = 1.0
    """An opening set back further than this from every facade plane (or not facing one)
    belongs to no facade: a dormer's or a roof window's."""
    min_hole_cover: float = 0.5
    """A hole in a wall polygon is an opening's (its rough opening, counted as that window or
    door) when the openings' own polygons cover at least this share of it; less covered holes
    (a passage, an arcade) stay holes."""
    floor_height_m: float = _MESH.floor_height_m
    """Storey height: floors = round(height / floor_height_m), at least 1."""

    def __post_init__(self) -> None:
        # The shared tolerances are checked where they are defined.
        ImportConfig(**{name: getattr(self, name) for name in _SHARED})
        if self.max_opening_depth_m <= 0:
            raise ValueError(f"max_opening_depth_m must be > 0 m, got {self.max_opening_depth_m}")
        if not 0 < self.min_hole_cover <= 1:
            raise ValueError(f"min_hole_cover must be in (0, 1], got {self.min_hole_cover}")
