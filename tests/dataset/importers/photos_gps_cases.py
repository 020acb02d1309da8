"""Shared cases of the ``--gps`` tests (test_photos_gps.py, test_photos_gps_command.py):
where the synthetic photos are taken, cameras on a ring and the frame they are moved into
(as structure from motion would give them), and EXIF GPS blocks written with Pillow."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
from PIL import ExifTags, Image
from PIL.TiffImagePlugin import IFDRational
from scipy.spatial.transform import Rotation

from dataset.importers.photos.gps import GpsFix, LocalOrigin, wgs84_from_east_north
from envelope.camera import Intrinsics, look_at

ORIGIN = LocalOrigin(48.8583701, 2.2944813)
"""Where the synthetic photos are taken (degrees, WGS84)."""
K = Intrinsics(90.0, 90.0, 48.0, 32.0, 96, 64)
TURN = Rotation.from_euler("xyz", [30, -50, 110], degrees=True).as_matrix()
SHRINK = 0.25
SHIFT = np.array([1.0, -2.0, 0.5])
G = ExifTags.GPS


def true_poses(n: int = 8, radius_m: float = 25.0) -> np.ndarray:
    """(n, 4, 4) level-ish cameras on a ring of ``radius_m`` round the origin, +y north."""
    return np.stack([look_at([radius_m * np.cos(a), radius_m * np.sin(a), 1.5 + (i % 3)],
                             [0, 0, 3]) for i, a in
                     enumerate(np.linspace(0, 2 * np.pi, n, endpoint=False))])


def moved_pose(pose: np.ndarray) -> np.ndarray:
    """``pose`` in the frame structure from motion would give: turned, shrunk, shifted."""
    out = np.eye(4)
    out[:3, :3] = TURN @ pose[:3, :3]
    out[:3, 3] = SHRINK * TURN @ pose[:3, 3] + SHIFT
    return out


def _dms(value_deg: float) -> tuple[IFDRational, IFDRational, IFDRational]:
    """EXIF degrees, minutes, seconds of ``abs(value_deg)`` (seconds as a fine fraction)."""
    exact = Fraction(abs(value_deg))
    degrees = int(exact)
    minutes = int((exact - degrees) * 60)
    seconds = ((exact - degrees) * 60 - minutes) * 60
    return (IFDRational(degrees), IFDRational(minutes),
            IFDRational(seconds.limit_denominator(10 ** 6)))


def gps_exif(latitude_deg: float, longitude_deg: float, **extra) -> Image.Exif:
    """An EXIF block holding one GPS position, written with Pillow's Exif API."""
    exif = Image.Exif()
    gps = exif.get_ifd(ExifTags.IFD.GPSInfo)
    gps[G.GPSLatitudeRef] = "N" if latitude_deg >= 0 else "S"
    gps[G.GPSLatitude] = _dms(latitude_deg)
    gps[G.GPSLongitudeRef] = "E" if longitude_deg >= 0 else "W"
    gps[G.GPSLongitude] = _dms(longitude_deg)
    for tag, value in extra.items():
        gps[getattr(G, tag)] = value
    return exif


def fix_at(east_north: np.ndarray) -> GpsFix:
    """The GPS fix of a place (m east, north of :data:`ORIGIN`)."""
    latitude, longitude = wgs84_from_east_north(east_north, ORIGIN)[0]
    return GpsFix(float(latitude), float(longitude))
