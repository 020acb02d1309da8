"""How a labelled mesh becomes a building: :class:`ImportConfig`, one place for the import
options of the mesh and IFC sources (:mod:`dataset.importers.mesh.building_file`).

``python -m dataset.generate --mesh/--ifc`` and ``python -m dataset.importer`` offer every
field as an option (``--ground-z``, ``--footprint-height-m``, ...; :mod:`dataset.source_args`).
"""

from __future__ import annotations

from dataclasses import dataclass

from dataset.importers.mesh.mesh_files import UpAxis
from envelope.geometry.visibility import MIN_ESCAPE_FRACTION, RAY_OFFSET_M


@dataclass(frozen=True)
class ImportConfig:
    """How a labelled mesh becomes a building; lengths in metres, angles in degrees."""

    up_axis: UpAxis = "z"
    """The file's up axis: glTF exported by Blender is y-up."""
    recentre: bool = True
    """Move the mesh so that its x/y bounding-box centre is at the origin and its ground at
    z = 0 (docs/DESIGN.md's world); the shift is recorded in the truth's ``extra``."""
    ground_z_m: float | None = None
    """Ground level in the file's frame (after ``up_axis``): faces and face parts below it
    are underground, never facade; ``None``: the mesh's lowest point."""
    max_tilt_deg: float = 10.0
    """Faces whose normal is further than this from horizontal (roof-like) are no facade."""
    angle_tolerance_deg: float = 10.0
    """Faces within this angle of a facade's direction join it (curved walls: sectors)."""
    offset_tolerance_m: float = 0.3
    """Parallel planes closer than this are one facade (windows set back into the wall)."""
    gap_tolerance_m: float = 0.05
    """Coplanar wall pieces further apart than this along the wall are different facades."""
    min_facade_width_m: float = 0.5
    """Narrower groups (window reveals, pilaster sides) belong to no facade."""
    rays_per_sample: int = 16
    """Ray directions per sample point (4 points per face) for the visibility test."""
    min_escape_fraction: float = MIN_ESCAPE_FRACTION
    """A face is seen from outside if at least this fraction of its rays escape."""
    ray_offset_m: float = RAY_OFFSET_M
    """Rays start this far off the surface (embree works in float32)."""
    footprint_height_m: float = 0.05
    """The footprint is the cross-section this far above the ground."""
    floor_height_m: float = 3.0
    """Storey height: floors = round(height / floor_height_m), at least 1."""

    def __post_init__(self) -> None:
        if self.up_axis not in ("z", "y"):
            raise ValueError(f"up_axis must be 'z' or 'y', got {self.up_axis!r}")
        for name in ("max_tilt_deg", "angle_tolerance_deg"):
            if not 0 < getattr(self, name) < 90:
                raise ValueError(f"{name} must be in (0, 90) degrees, got {getattr(self, name)}")
        for name in ("offset_tolerance_m", "gap_tolerance_m", "min_facade_width_m"):
            if getattr(self, name) < 0:
                raise ValueError(f"{name} must be >= 0 m, got {getattr(self, name)}")
        for name in ("ray_offset_m", "footprint_height_m", "floor_height_m"):
            if getattr(self, name) <= 0:
                raise ValueError(f"{name} must be > 0 m, got {getattr(self, name)}")
        if self.rays_per_sample < 1:
            raise ValueError(f"rays_per_sample must be >= 1, got {self.rays_per_sample}")
        if not 0 < self.min_escape_fraction <= 1:
            raise ValueError(
                f"min_escape_fraction must be in (0, 1], got {self.min_escape_fraction}"
            )
