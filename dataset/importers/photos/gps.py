"""Where each photo was taken, from its EXIF GPS tags, in metres east and north of a local
origin (docs/importing.md, section 9, says what is assumed).

- **Reading**: latitude and longitude are EXIF degrees, minutes and seconds (three
  rationals) with a hemisphere (``N``/``S``, ``E``/``W``), read with Pillow. A photo has
  no fix when a tag is missing, a rational has a zero denominator, the receiver marked
  the measurement void (``GPSStatus`` ``V``), the position is out of range, or it is
  exactly (0, 0) (what some cameras write without a fix). Positions are taken as WGS84
  (what GPS receivers report). Altitude and ``GPSImgDirection`` (the compass) are read
  but never give the scale or north: consumer GPS altitude errs by tens of metres and a
  phone's compass by tens of degrees near buildings.
- **Metres**: a transverse Mercator projection (PROJ, through pyproj) centred on the
  fixes' mean latitude and longitude, scale 1 on its central meridian. It is conformal
  and needs no altitude (unlike a geocentric east-north-up frame, whose horizontal axes
  depend on the height given), and near its centre it is the local tangent plane: within
  1 km of the centre its scale differs from 1 by under (1 km / 6371 km)² / 2 = 1.3e-8,
  and its grid north from true north by under 1 km x tan(latitude) / 6371 km (0.016° at
  60° of latitude; 0.002° within 100 m, a building's size). So +y of these metres is
  true north, +x east.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
from PIL import ExifTags, Image, UnidentifiedImageError

_HEMISPHERE_SIGN = {"N": 1.0, "S": -1.0, "E": 1.0, "W": -1.0}


@dataclass(frozen=True)
class GpsFix:
    """One photo's EXIF GPS position: WGS84 ``latitude_deg`` (north positive) and
    ``longitude_deg`` (east positive); ``altitude_m`` above sea level and
    ``img_direction_deg`` (the way the camera looked, clockwise from north; ``"T"`` true or
    ``"M"`` magnetic in ``img_direction_ref``) where the photo has them."""

    latitude_deg: float
    longitude_deg: float
    altitude_m: float | None = None
    img_direction_deg: float | None = None
    img_direction_ref: str | None = None


@dataclass(frozen=True)
class LocalOrigin:
    """The centre of the local metres (:func:`east_north_m`), WGS84 degrees."""

    latitude_deg: float
    longitude_deg: float


def degrees_from_exif(dms: Sequence[Any], hemisphere: str) -> float | None:
    """Signed degrees from EXIF (degrees, minutes, seconds) and its hemisphere letter.

    Each value may be a Pillow ``IFDRational``, a ``(numerator, denominator)`` pair (as
    piexif gives them) or a number. ``None`` when the values are not three finite numbers
    (a zero denominator) or the hemisphere is not one of N, S, E, W.
    """
    if hemisphere not in _HEMISPHERE_SIGN or len(dms) != 3:
        return None
    values = [_number(v) for v in dms]
    if any(v is None or not math.isfinite(v) or v < 0 for v in values):
        return None
    degrees, minutes, seconds = values
    return _HEMISPHERE_SIGN[hemisphere] * (degrees + minutes / 60.0 + seconds / 3600.0)


def gps_fix_from_exif(gps: dict[int, Any]) -> GpsFix | None:
    """The fix in a GPS IFD (tag number -> value, as Pillow's ``Exif.get_ifd`` gives it),
    or ``None`` where it holds none (module docstring)."""
    if _text(gps.get(ExifTags.GPS.GPSStatus)) == "V":
        return None
    latitude = degrees_from_exif(gps.get(ExifTags.GPS.GPSLatitude, ()),
                                 _text(gps.get(ExifTags.GPS.GPSLatitudeRef)))
    longitude = degrees_from_exif(gps.get(ExifTags.GPS.GPSLongitude, ()),
                                  _text(gps.get(ExifTags.GPS.GPSLongitudeRef)))
    if (latitude is None or longitude is None or abs(latitude) > 90 or abs(longitude) > 180
            or latitude == longitude == 0.0):
        return None
    altitude = _number(gps.get(ExifTags.GPS.GPSAltitude))
    if altitude is not None and gps.get(ExifTags.GPS.GPSAltitudeRef) in (1, b"\x01"):
        altitude = -altitude  # reference 1: below sea level
    direction = _number(gps.get(ExifTags.GPS.GPSImgDirection))
    direction_ref = _text(gps.get(ExifTags.GPS.GPSImgDirectionRef)) or None
    return GpsFix(latitude, longitude,
                  altitude if altitude is not None and math.isfinite(altitude) else None,
                  direction if direction is not None and math.isfinite(direction) else None,
                  direction_ref if direction is not None else None)


def read_gps_fix(path: str | Path) -> GpsFix | None:
    """The EXIF GPS fix of the photo at ``path``, or ``None`` where it has none.

    Raises
    ------
    ValueError
        The file is not an image Pillow can open.
    """
    try:
        with Image.open(path) as img:
            gps = dict(img.getexif().get_ifd(ExifTags.IFD.GPSInfo))
    except (UnidentifiedImageError, OSError, SyntaxError, ValueError) as exc:
        raise ValueError(f"{path}: not an image Pillow can read ({exc}); copy the file again "
                         "or re-save it as JPEG") from exc
    return gps_fix_from_exif(gps)


def mean_origin(fixes: Sequence[GpsFix]) -> LocalOrigin:
    """The fixes' mean latitude and longitude (a building's fixes are metres apart, far
    from the antimeridian)."""
    return LocalOrigin(float(np.mean([f.latitude_deg for f in fixes])),
                       float(np.mean([f.longitude_deg for f in fixes])))


def east_north_m(latitude_deg: np.ndarray, longitude_deg: np.ndarray,
                 origin: LocalOrigin) -> np.ndarray:
    """(N, 2) metres east and north of ``origin`` of WGS84 positions ((N,) degrees each),
    in the transverse Mercator centred there (module docstring)."""
    east, north = _transformer(origin.latitude_deg, origin.longitude_deg, False).transform(
        np.asarray(longitude_deg, dtype=np.float64), np.asarray(latitude_deg, dtype=np.float64))
    return np.column_stack([east, north])


def wgs84_from_east_north(east_north: np.ndarray, origin: LocalOrigin) -> np.ndarray:
    """(N, 2) WGS84 (latitude, longitude) degrees of (N, 2) metres east and north of
    ``origin``: the inverse of :func:`east_north_m`."""
    east_north = np.atleast_2d(np.asarray(east_north, dtype=np.float64))
    longitude, latitude = _transformer(origin.latitude_deg, origin.longitude_deg,
                                       True).transform(east_north[:, 0], east_north[:, 1])
    return np.column_stack([latitude, longitude])


@lru_cache(maxsize=8)
def _transformer(latitude_deg: float, longitude_deg: float, inverse: bool):
    from pyproj import CRS, Transformer  # imported here: for this option alone

    local = CRS.from_proj4(f"+proj=tmerc +lat_0={latitude_deg!r} +lon_0={longitude_deg!r} "
                           "+k=1 +x_0=0 +y_0=0 +datum=WGS84 +units=m +no_defs")
    wgs84 = CRS.from_epsg(4326)
    return (Transformer.from_crs(local, wgs84, always_xy=True) if inverse
            else Transformer.from_crs(wgs84, local, always_xy=True))


def _number(value: Any) -> float | None:
    if value is None:
        return None
    if isinstance(value, tuple) and len(value) == 2:  # (numerator, denominator)
        return value[0] / value[1] if value[1] else math.nan
    try:
        return float(value)
    except (TypeError, ValueError, ZeroDivisionError):
        return None


def _text(value: Any) -> str:
    if isinstance(value, bytes):
        value = value.decode("latin-1")
    return str(value).strip().rstrip("\x00").upper() if value is not None else ""
