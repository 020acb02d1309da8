"""Metres and z up: the similarity that takes a structure-from-motion frame (any scale, any
orientation) to the project's world (metres, z up, ground at z = 0), from what the user
knows (docs/importing.md, section 9, says what is assumed).

- **Up** from the cameras: photos are taken without roll (the EXIF orientation is applied
  first, so every image is upright), so every camera's x axis (image right) is horizontal
  and up is the direction most perpendicular to all of them: the eigenvector of the least
  eigenvalue of sum x xᵀ, signed to agree with the cameras' mean y axis (image up). Exact
  for any pitch when the photos face two directions or more. When they all face one way
  (their x axes spread less than :data:`MIN_HEADING_SPREAD`), up is the cameras' mean y axis
  made perpendicular to their x axes (exact only for level cameras).
- **Scale** from one thing the user knows: the distance between two cameras (two photos'
  names), or the building's height, taken as the span of the sparse points along up from
  their :data:`GROUND_PERCENTILE` to their :data:`TOP_PERCENTILE`; or from the photos' EXIF
  GPS positions (:mod:`dataset.importers.photos.gps_fit`), which give true north too; or
  from a city model of the place (:mod:`dataset.importers.photos.city_fit`), which gives
  north and the model's position too. Nothing known: refused.
- **Where**: with a city model, its building's frame (as ``--citygml`` imports it); else,
  with sparse points, the ground (z = 0) at their :data:`GROUND_PERCENTILE` along up and the
  origin above their median; without (a nerfstudio file), the input's origin.
- **North**: with GPS, the world's +y is true north and +x east; with a city model, +y is
  its CRS's grid north; otherwise north is unknown and +y is the way the first photo looks
  (level).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from dataset.importers.photos.city_fit import CityFitConfig, fit_city_model
from dataset.importers.photos.city_target import CityTarget
from dataset.importers.photos.gps import GpsFix
from dataset.importers.photos.gps_frame import gps_frame

MIN_HEADING_SPREAD = 0.01
"""The second-least eigenvalue of sum x xᵀ per camera below which the photos face one way
(their x axes within about 6 degrees: sin² 6° ≈ 0.01)."""
GROUND_PERCENTILE = 1.0
TOP_PERCENTILE = 99.0
"""The sparse points' percentiles along up taken for the ground and the building's top (a
few stray points below the ground or above the roof change nothing)."""
SCALE_OPTIONS = ("--known-distance PHOTO_A PHOTO_B METRES, --known-height METRES, --gps or "
                 "--city-model FILE_OR_DIR")
NO_SCALE = (f"photos carry no scale: say what you know, with {SCALE_OPTIONS} (the photos' "
            "EXIF GPS positions, or a CityGML model of the place, which give north too; "
            "docs/importing.md, section 9)")


@dataclass(frozen=True)
class KnownDistance:
    """The distance in metres between the cameras that took two photos (by file name)."""

    photo_a: str
    photo_b: str
    metres: float


@dataclass(frozen=True)
class ScaleHint:
    """What the user knows of the scale: one of a known distance between two cameras, the
    building's height in metres, ``gps``: the photos' EXIF GPS positions, or
    ``city_model``: a CityGML file or folder of the place (``city_building``: the id of the
    building the photos show, where it holds several)."""

    known_distance: KnownDistance | None = None
    known_height_m: float | None = None
    gps: bool = False
    city_model: Path | None = None
    city_building: str | None = None

    def __post_init__(self) -> None:
        given = ((self.known_distance is not None) + (self.known_height_m is not None)
                 + self.gps + (self.city_model is not None))
        if given == 0:
            raise ValueError(NO_SCALE)
        if given > 1:
            raise ValueError(f"give one scale, not {given}: {SCALE_OPTIONS}")
        if self.city_building is not None and self.city_model is None:
            raise ValueError("--city-building names a building of --city-model: give both")
        if self.gps or self.city_model is not None:
            return
        value = (self.known_distance.metres if self.known_distance is not None
                 else self.known_height_m)
        if not (np.isfinite(value) and value > 0):
            raise ValueError(f"a known distance or height must be a positive number of "
                             f"metres, got {value}")
        if self.known_distance is not None and (self.known_distance.photo_a
                                                == self.known_distance.photo_b):
            raise ValueError("--known-distance needs two different photos")


@dataclass(frozen=True)
class Similarity:
    """``world = scale * rotation @ p + translation_m`` for a point ``p`` of the input frame."""

    scale: float
    rotation: np.ndarray
    translation_m: np.ndarray

    def points(self, points: np.ndarray) -> np.ndarray:
        """(N, 3) input-frame points in the world (m)."""
        return self.scale * np.asarray(points, dtype=np.float64) @ self.rotation.T \
            + self.translation_m

    def pose(self, world_from_camera: np.ndarray) -> np.ndarray:
        """(4, 4) a camera-to-world pose of the input frame in the world (still rigid)."""
        pose = np.eye(4)
        pose[:3, :3] = self.rotation @ np.asarray(world_from_camera)[:3, :3]
        pose[:3, 3] = self.points(np.asarray(world_from_camera)[None, :3, 3])[0]
        return pose


def up_from_cameras(world_from_camera: np.ndarray) -> tuple[np.ndarray, str]:
    """The unit up direction of the input frame from (N, 4, 4) OpenGL camera-to-world poses,
    and how it was found (module docstring)."""
    poses = np.asarray(world_from_camera, dtype=np.float64)
    x_axes, y_axes = poses[:, :3, 0], poses[:, :3, 1]
    values, vectors = np.linalg.eigh(x_axes.T @ x_axes / len(poses))
    mean_y = y_axes.mean(axis=0)
    if values[1] >= MIN_HEADING_SPREAD:
        up, how = vectors[:, 0], "perpendicular to the cameras' x axes (photos without roll)"
    else:
        along = vectors[:, 2]
        up = mean_y - (mean_y @ along) * along
        how = ("the cameras' mean y axis (the photos all face one way: level cameras "
               "assumed)")
    up = up / np.linalg.norm(up)
    return (up if up @ mean_y >= 0 else -up), how


def metric_similarity(world_from_camera: np.ndarray, names: Sequence[str],
                      points: np.ndarray | None, hint: ScaleHint,
                      gps_fixes: Sequence[GpsFix | None] | None = None,
                      city: CityTarget | None = None) -> tuple[Similarity, dict]:
    """The similarity from the input frame to the world, and a record of what it assumed.

    Parameters
    ----------
    world_from_camera : (N, 4, 4) OpenGL camera-to-world poses in the input frame
    names : the N photos' names
    points : (M, 3) sparse points in the input frame, or ``None``
    gps_fixes : the N photos' EXIF GPS fixes (``None`` where a photo has none); needed
        with ``hint.gps``
    city : the city model's surfaces (:func:`dataset.importers.photos.city_target.
        read_city_target`); needed with ``hint.city_model``

    Raises
    ------
    ValueError
        A known distance names a photo that has no pose, or two cameras at one place; a
        known height without sparse points; GPS fixes too few, too close together or
        disagreeing (:func:`dataset.importers.photos.gps_fit.fit_gps`); a city model
        without sparse points, or a fit to it that is bad or ambiguous
        (:func:`dataset.importers.photos.city_fit.fit_city_model`).
    """
    poses = np.asarray(world_from_camera, dtype=np.float64)
    up, up_how = up_from_cameras(poses)
    right = poses[0, :3, 0] - (poses[0, :3, 0] @ up) * up
    if np.linalg.norm(right) < 1e-6:
        raise ValueError(f"the first photo ({names[0]}) looks straight up or down: put a "
                         "photo taken level first")
    right /= np.linalg.norm(right)
    rotation = np.stack([right, np.cross(up, right), up])
    if hint.city_model is not None:
        return _city_similarity(poses, points, rotation, up_how, city)
    if hint.gps:
        if gps_fixes is None or len(gps_fixes) != len(poses):
            raise ValueError("--gps needs each posed photo's GPS fix (None where it has none)")
        gps = gps_frame(poses, names, rotation, gps_fixes)
        scale, rotation = gps.scale, gps.turn_z @ rotation
        scale_how = (f"GPS: the EXIF positions of {int(gps.fit.kept.sum())} photos, "
                     "horizontal similarity fit (altitude not used)")
    else:
        scale, scale_how = _scale(poses, list(names), points, up, hint)
    if points is None or len(points) == 0:
        translation = np.zeros(3)
        where = "the input's origin (no sparse points)"
    else:
        turned = scale * np.asarray(points, dtype=np.float64) @ rotation.T
        translation = -np.array([*np.median(turned[:, :2], axis=0),
                                 np.percentile(turned[:, 2], GROUND_PERCENTILE)])
        where = (f"ground at the sparse points' {GROUND_PERCENTILE:g}th percentile along up, "
                 "origin above their median")
    record = {"up": up_how, "scale": scale_how, "origin": where,
              "scale_source": ("gps" if hint.gps else "known_distance"
                               if hint.known_distance is not None else "known_height"),
              "north_known": hint.gps,
              "north": ("true north: +y points north, +x east (from the GPS positions)"
                        if hint.gps else
                        f"unknown: +y is the way the first photo ({names[0]}) looks")}
    if hint.gps:
        record["north_deg"] = 0.0  # envelope.orientation: +y is true north
        record["gps"] = gps.record(translation[:2])
    return Similarity(scale, rotation, translation), record


def _scale(poses: np.ndarray, names: list[str], points: np.ndarray | None, up: np.ndarray,
           hint: ScaleHint) -> tuple[float, str]:
    known = hint.known_distance
    if known is not None:
        missing = [n for n in (known.photo_a, known.photo_b) if n not in names]
        if missing:
            raise ValueError(f"--known-distance names {', '.join(missing)}, which has no "
                             f"camera pose (posed photos: {', '.join(names[:5])}"
                             f"{' ...' if len(names) > 5 else ''})")
        span = np.linalg.norm(poses[names.index(known.photo_a), :3, 3]
                              - poses[names.index(known.photo_b), :3, 3])
        if span <= 1e-9 * max(1.0, float(np.abs(poses[:, :3, 3]).max())):
            raise ValueError(f"{known.photo_a} and {known.photo_b} were taken from one place: "
                             "name two photos taken metres apart")
        return known.metres / span, (f"known distance {known.metres:g} m between the cameras "
                                     f"of {known.photo_a} and {known.photo_b}")
    if points is None or len(points) == 0:
        raise ValueError("--known-height needs the sparse points of structure from motion, "
                         "which this input lacks: give --known-distance instead")
    heights = np.asarray(points, dtype=np.float64) @ up
    span = np.percentile(heights, TOP_PERCENTILE) - np.percentile(heights, GROUND_PERCENTILE)
    return hint.known_height_m / span, (
        f"known building height {hint.known_height_m:g} m over the sparse points' "
        f"{GROUND_PERCENTILE:g}th to {TOP_PERCENTILE:g}th percentile along up")


def _city_similarity(poses: np.ndarray, points: np.ndarray | None, level: np.ndarray,
                     up_how: str, city: CityTarget | None) -> tuple[Similarity, dict]:
    """The similarity that the fit to the city model gives, and its record."""
    if city is None:
        raise ValueError("--city-model needs the city model read first (read_city_target)")
    if points is None or len(points) == 0:
        raise ValueError("--city-model needs the sparse points of structure from motion, "
                         "which this input lacks: give --known-distance instead")
    levelled = np.asarray(points, dtype=np.float64) @ level.T
    ground_z, top_z = np.percentile(levelled[:, 2], (GROUND_PERCENTILE, TOP_PERCENTILE))
    fit = fit_city_model(levelled, poses[:, :3, 3] @ level.T, float(ground_z), float(top_z),
                         city)
    best = fit.best.similarity
    record = {"up": up_how,
              "scale": (f"city model: the sparse points fitted to building {city.building} "
                        f"and {len(city.neighbours)} neighbours ({fit.best.inliers} of "
                        f"{fit.points_used} within {fit.best.residuals.trim_m:g} m of a "
                        "surface)"),
              "origin": (f"the city model's building frame: world = {city.crs} coordinates "
                         f"+ offset_m {[round(float(x), 4) for x in city.offset_m]} (as "
                         "--citygml imports the building)"),
              "scale_source": "city_model", "north_known": True,
              "north": (f"grid north of {city.crs}: +y points along it, +x east; true north "
                        f"lies {city.north_deg:.3f} degrees anticlockwise of +y (the "
                        "meridian convergence)"),
              "north_deg": city.north_deg,  # envelope.orientation: true north to +y, clockwise
              "city_model": fit.record(city, CityFitConfig())}
    return Similarity(best.scale, best.turn_z @ level, best.shift_m.copy()), record
