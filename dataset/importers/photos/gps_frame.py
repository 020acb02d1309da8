"""The photos' GPS fixes as the metric frame reads them: scale and the turn about z that makes
+y true north (:func:`dataset.importers.photos.gps_fit.fit_gps`), and what the scene's
``photos`` record says of them (docs/importing.md, section 9).

True north comes from the GPS positions, WGS84 latitude and longitude, not from a compass:
magnetic declination plays no part. The EXIF ``GPSImgDirection`` (the phone's compass),
where photos have it, is only compared with the fitted headings in the record.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from dataset.importers.photos.gps import (
    GpsFix,
    LocalOrigin,
    east_north_m,
    mean_origin,
    wgs84_from_east_north,
)
from dataset.importers.photos.gps_fit import (
    GPS_ERROR_M,
    MIN_SPREAD_M,
    OUTLIER_M,
    GpsFit,
    check_fixes,
    fit_gps,
)


@dataclass(frozen=True)
class GpsFrame:
    """The fit of the levelled camera centres onto their GPS metres: ``scale``, ``turn_z``
    ((3, 3), about z, from the levelled frame to east, north, up), the local ``origin`` of
    the metres, the ``fit`` (over the photos with a fix), the posed photos' ``names``, the
    indices of those ``with_fix`` (the fit's order) and the ``compass`` comparison."""

    scale: float
    turn_z: np.ndarray
    origin: LocalOrigin
    fit: GpsFit
    names: tuple[str, ...]
    with_fix: tuple[int, ...]
    compass: dict

    def record(self, translation_xy_m: np.ndarray) -> dict:
        """The ``gps`` entry of the scene's ``photos`` record, given the world's horizontal
        translation (the world's x = y = 0 gets its WGS84 latitude and longitude)."""
        kept = self.fit.residuals_m[self.fit.kept]
        rms = float(np.sqrt(np.mean(kept ** 2)))
        # east, north = world x, y - translation + the fit's translation
        latitude, longitude = wgs84_from_east_north(
            self.fit.similarity.translation_m - np.asarray(translation_xy_m), self.origin)[0]
        return {
            "posed_photos_with_fix": len(self.with_fix), "posed_photos": len(self.names),
            "fixes_kept": int(self.fit.kept.sum()),
            "fixes_left_out": {self.names[self.with_fix[i]]:
                               round(float(self.fit.residuals_m[i]), 2)
                               for i in np.flatnonzero(~self.fit.kept)},
            "outlier_threshold_m": OUTLIER_M,
            "residual_median_m": round(float(np.median(kept)), 3),
            "residual_max_m": round(float(kept.max()), 3),
            "spread_m": round(self.fit.spread_m, 2), "min_spread_m": MIN_SPREAD_M,
            "assumed_fix_error_m": GPS_ERROR_M,
            "scale_error_estimate": round(rms / self.fit.spread_m, 4),
            "origin_latitude_deg": round(float(latitude), 8),
            "origin_longitude_deg": round(float(longitude), 8),
            "projection": "transverse Mercator centred on the fixes' mean, WGS84",
            "altitude": "not used (consumer GPS altitude errs by tens of metres)",
            "compass": self.compass,
        }


def fixes_east_north(fixes: Sequence[GpsFix | None]) -> tuple[tuple[int, ...],
                                                              LocalOrigin | None, np.ndarray]:
    """Which of the photos have a fix, the fixes' mean, and their (K, 2) metres east and
    north of it."""
    with_fix = tuple(i for i, f in enumerate(fixes) if f is not None)
    if not with_fix:
        return with_fix, None, np.zeros((0, 2))
    chosen = [fixes[i] for i in with_fix]
    origin = mean_origin(chosen)
    return with_fix, origin, east_north_m(np.array([f.latitude_deg for f in chosen]),
                                          np.array([f.longitude_deg for f in chosen]), origin)


def check_photo_fixes(fixes: Sequence[GpsFix | None]) -> None:
    """Refuse the photos' fixes before anything runs: too few, or too close together.

    Raises
    ------
    ValueError
        As :func:`dataset.importers.photos.gps_fit.check_fixes`.
    """
    check_fixes(fixes_east_north(fixes)[2], len(fixes))


def gps_frame(world_from_camera: np.ndarray, names: Sequence[str], level: np.ndarray,
              fixes: Sequence[GpsFix | None]) -> GpsFrame:
    """The scale and north of (N, 4, 4) camera-to-world poses (input frame) from their
    photos' fixes (``None`` where a photo has none); ``level`` is the (3, 3) rotation from
    the input frame to one with z up.

    Raises
    ------
    ValueError
        Too few fixes, too close together, or too few agreeing
        (:func:`dataset.importers.photos.gps_fit.fit_gps`).
    """
    poses = np.asarray(world_from_camera, dtype=np.float64)
    with_fix, origin, east_north = fixes_east_north(fixes)
    fit = fit_gps((poses[list(with_fix), :3, 3] @ level.T)[:, :2], east_north, len(fixes))
    heading = fit.similarity.heading_rad
    turn_z = np.array([[np.cos(heading), -np.sin(heading), 0.0],
                       [np.sin(heading), np.cos(heading), 0.0], [0.0, 0.0, 1.0]])
    compass = _compass_check(poses, fixes, turn_z @ level)
    return GpsFrame(fit.similarity.scale, turn_z, origin, fit, tuple(names), with_fix,
                    compass)


def _compass_check(poses: np.ndarray, fixes: Sequence[GpsFix | None],
                   rotation: np.ndarray) -> dict:
    """How far the EXIF ``GPSImgDirection`` of the photos that have one lies from their
    camera's fitted heading (median of the absolute differences, degrees)."""
    pairs = [(i, f) for i, f in enumerate(fixes)
             if f is not None and f.img_direction_deg is not None]
    if not pairs:
        return {"photos": 0}
    forward = -(rotation @ poses[[i for i, _ in pairs], :3, :3])[:, :, 2]
    heading_deg = np.degrees(np.arctan2(forward[:, 0], forward[:, 1]))
    difference = (np.array([f.img_direction_deg for _, f in pairs]) - heading_deg + 180.0) \
        % 360.0 - 180.0
    references = sorted({f.img_direction_ref or "unknown" for _, f in pairs})
    return {"photos": len(pairs),
            "median_abs_difference_deg": round(float(np.median(np.abs(difference))), 2),
            "reference": references,
            "note": "compared only: north comes from the GPS positions ('M', magnetic, "
                    "directions are off by the declination besides)"}
