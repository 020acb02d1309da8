"""Facade orientation: outward azimuth from true north and its EnergyPlus bin, defined once.

Conventions (every export prints :data:`CONVENTIONS`):

- **Azimuth**: the horizontal part of a facade's outward normal, in degrees
  clockwise from true north, in [0, 360).
- **North**: ``north_deg`` is the clockwise angle from true north to the world
  +y axis (EnergyPlus ``Building`` "North Axis", OpenStudio ``northAxis``, IFC
  ``TrueNorth`` read by IfcOpenShell's ``get_true_north``). A facade whose
  outward normal is world +y faces ``north_deg``. Procedural scenes state
  ``north_deg = 0`` (+y is true north, ``north_source = "convention"``).
- **Bins** (EnergyPlus "Window-Wall Ratio" table, OpenStudio's
  SetWindowToWallRatioByFacade, Honeybee's ``face_orient_index``): N [315, 45),
  E [45, 135), S [135, 225), W [225, 315): a lower bound belongs to its bin, so
  45 is E, 135 S, 225 W and 315 N.
- **Areas**: gross = wall + window + door, net wall = wall (opaque, no door);
  WWR = window / gross (:func:`envelope.wwr.wwr_from_areas`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Literal

import numpy as np

OrientationBin = Literal["N", "E", "S", "W"]
ORIENTATION_BINS: tuple[OrientationBin, ...] = ("N", "E", "S", "W")
BIN_NAMES: dict[OrientationBin, str] = {"N": "north", "E": "east", "S": "south", "W": "west"}
BIN_CENTRE_DEG: dict[OrientationBin, float] = {"N": 0.0, "E": 90.0, "S": 180.0, "W": 270.0}
BIN_HALF_WIDTH_DEG = 45.0

NorthSource = Literal["convention", "ifc_true_north", "ifc_map_conversion", "crs_convergence",
                      "user"]
NORTH_SOURCES: tuple[str, ...] = ("convention", "ifc_true_north", "ifc_map_conversion",
                                  "crs_convergence", "user")
"""Where ``north_deg`` comes from: ``convention`` (+y is true north unless the source says
otherwise: procedural scenes, and imported files that give no north), the IFC model's
``TrueNorth`` or its ``IfcMapConversion`` (grid north), the meridian convergence of a
georeferenced file's projected CRS at the building (+y is the CRS's grid north: CityGML,
:mod:`dataset.importers.citygml.grid_north`), or the user (``--north-deg``)."""

MIN_HORIZONTAL_NORMAL = 1e-6  # a normal this close to vertical has no azimuth

CONVENTIONS: tuple[str, ...] = (
    "azimuth: outward facade normal, degrees clockwise from true north, in [0, 360)",
    "north_deg: clockwise angle from true north to the world +y axis "
    "(EnergyPlus Building North Axis); 0 = +y is true north",
    "bins: N [315, 45), E [45, 135), S [135, 225), W [225, 315); a lower bound belongs "
    "to its bin (45 is E, 315 is N)",
    "areas in m2: gross = wall + window + door; net wall = wall (opaque, doors excluded)",
    "WWR = window / gross, a fraction in [0, 1] (envelope.wwr); 0 means no windows; "
    "an empty value means not known",
)


def azimuth_deg_from_normal(normal_world: Sequence[float], north_deg: float = 0.0
                            ) -> float | None:
    """Outward azimuth (degrees clockwise from true north, [0, 360)) of a world-frame normal.

    Parameters
    ----------
    normal_world : (3,) float
        Outward normal, world frame (z up); need not be unit length.
    north_deg : float
        Clockwise angle from true north to world +y (module docstring).

    Returns
    -------
    float or None
        ``None`` when the normal is (nearly) vertical: a roof or floor has no azimuth.

    Raises
    ------
    ValueError
        If the normal is not 3 finite numbers or ``north_deg`` is not finite.
    """
    n = np.asarray(normal_world, dtype=np.float64)
    if n.shape != (3,) or not np.all(np.isfinite(n)):
        raise ValueError(f"a normal needs 3 finite numbers, got {normal_world!r}")
    if not math.isfinite(north_deg):
        raise ValueError(f"north_deg must be a finite angle in degrees, got {north_deg}")
    length = float(np.linalg.norm(n))
    if length == 0 or math.hypot(n[0], n[1]) <= MIN_HORIZONTAL_NORMAL * length:
        return None
    return _wrap_deg(math.degrees(math.atan2(n[0], n[1])) + north_deg)


def orientation_bin(azimuth_deg: float) -> OrientationBin:
    """The EnergyPlus bin of an azimuth in degrees (any real angle; wrapped to [0, 360)).

    N [315, 45), E [45, 135), S [135, 225), W [225, 315).

    Raises
    ------
    ValueError
        If ``azimuth_deg`` is not finite.
    """
    if not math.isfinite(azimuth_deg):
        raise ValueError(f"an azimuth must be a finite angle in degrees, got {azimuth_deg}")
    a = _wrap_deg(azimuth_deg)
    return ORIENTATION_BINS[int(((a + BIN_HALF_WIDTH_DEG) % 360.0) // 90.0)]


def true_north_xy_from_world(xy_world: np.ndarray, north_deg: float) -> np.ndarray:
    """World x/y rotated into a frame whose +y is true north and +x true east.

    xy_world : (..., 2) float, metres. Returns (..., 2) float: a world direction
    with azimuth ``a`` (clockwise from true north) points along
    ``(sin a, cos a)`` after the rotation, as in a projected map CRS.
    """
    xy = np.asarray(xy_world, dtype=np.float64)
    if xy.shape[-1] != 2:
        raise ValueError(f"expected (..., 2) x/y coordinates, got shape {xy.shape}")
    t = math.radians(north_deg)
    c, s = math.cos(t), math.sin(t)
    x, y = xy[..., 0], xy[..., 1]
    return np.stack([c * x + s * y, -s * x + c * y], axis=-1)


def _wrap_deg(angle_deg: float) -> float:
    a = float(angle_deg) % 360.0
    return 0.0 if a >= 360.0 else a  # -1e-17 % 360 rounds to 360.0
