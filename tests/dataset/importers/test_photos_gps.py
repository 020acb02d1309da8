"""dataset.importers.photos with ``--gps``: EXIF GPS tags read in closed form (and a real
phone photo's), WGS84 in local metres against the ellipsoid's radii, the plane similarity
exact and robust to a bad fix, and the metric frame with +y true north. The command line
and structure from motion: test_photos_gps_command.py."""

from __future__ import annotations

import math

import numpy as np
import pytest
from paths import REPO_ROOT
from photos_gps_cases import SHIFT, SHRINK, TURN, G, fix_at, gps_exif, moved_pose, true_poses
from PIL import ExifTags, Image
from PIL.TiffImagePlugin import IFDRational

from dataset.importers.photos.gps import (
    GpsFix,
    LocalOrigin,
    degrees_from_exif,
    east_north_m,
    gps_fix_from_exif,
    read_gps_fix,
    wgs84_from_east_north,
)
from dataset.importers.photos.gps_fit import (
    MIN_SPREAD_M,
    PlaneSimilarity,
    fit_gps,
    similarity_2d,
)
from dataset.importers.photos.metric_frame import ScaleHint, metric_similarity

EXACT = 1e-9
FIXTURE = REPO_ROOT / "tests" / "fixtures" / "photos_gps" / "IMG_20180725_163423-128px.jpg"
WGS84_A_M = 6378137.0
WGS84_F = 1 / 298.257223563



# --- EXIF tags ---------------------------------------------------------------------------

def test_exif_rationals_give_signed_degrees_in_closed_form():
    dms = (IFDRational(50), IFDRational(17), IFDRational(5857, 100))
    assert degrees_from_exif(dms, "N") == 50 + 17 / 60 + 58.57 / 3600
    assert degrees_from_exif(dms, "S") == -(50 + 17 / 60 + 58.57 / 3600)
    # piexif's (numerator, denominator) pairs and plain numbers read the same.
    assert degrees_from_exif(((11, 1), (53, 1), (645599999, 100000000)), "W") == \
        -(11 + 53 / 60 + 6.45599999 / 3600)
    assert degrees_from_exif((2.5, 0, 0), "E") == 2.5
    assert degrees_from_exif((IFDRational(1, 0), 0, 0), "N") is None  # zero denominator
    assert degrees_from_exif(dms, "") is None and degrees_from_exif(dms[:2], "N") is None


def test_a_gps_ifd_without_a_usable_fix_gives_none():
    good = {G.GPSLatitudeRef: "N", G.GPSLatitude: (10, 0, 0), G.GPSLongitudeRef: "E",
            G.GPSLongitude: (20, 30, 0)}
    assert gps_fix_from_exif(good) == GpsFix(10.0, 20.5)
    assert gps_fix_from_exif({}) is None
    assert gps_fix_from_exif({**good, G.GPSStatus: "V"}) is None  # measurement void
    assert gps_fix_from_exif({**good, G.GPSLatitude: (0, 0, 0), G.GPSLongitude: (0, 0, 0)}) \
        is None  # (0, 0): what some cameras write without a fix
    assert gps_fix_from_exif({**good, G.GPSLatitude: (95, 0, 0)}) is None
    below = gps_fix_from_exif({**good, G.GPSAltitudeRef: b"\x01", G.GPSAltitude: 12.5,
                               G.GPSImgDirectionRef: "M", G.GPSImgDirection: 123.25})
    assert below == GpsFix(10.0, 20.5, -12.5, 123.25, "M")


def test_gps_written_by_pillow_is_read_back(tmp_path):
    path = tmp_path / "p.jpg"
    Image.new("RGB", (16, 16)).save(path, exif=gps_exif(-33.8567844, 151.2152967,
                                                         GPSAltitude=IFDRational(58)))
    fix = read_gps_fix(path)
    assert fix.latitude_deg == pytest.approx(-33.8567844, abs=1e-12)
    assert fix.longitude_deg == pytest.approx(151.2152967, abs=1e-12)
    assert fix.altitude_m == 58.0
    Image.new("RGB", (16, 16)).save(tmp_path / "none.jpg")
    assert read_gps_fix(tmp_path / "none.jpg") is None


def test_a_real_phone_photo_gives_its_stated_position():
    fix = read_gps_fix(FIXTURE)
    # exifr's own tests state this photo's position (tests/fixtures/photos_gps/SOURCE.md).
    assert fix.latitude_deg == pytest.approx(50.29960277777778, abs=1e-12)
    assert fix.longitude_deg == pytest.approx(14.820294444444444, abs=1e-12)
    assert fix.altitude_m == 252.0
    with Image.open(FIXTURE) as img:
        raw = img.getexif().get_ifd(ExifTags.IFD.GPSInfo)
    assert raw[G.GPSLatitudeRef] == "N" and raw[G.GPSLongitudeRef] == "E"
    degrees, minutes, seconds = (float(v) for v in raw[G.GPSLatitude])
    assert fix.latitude_deg == degrees + minutes / 60 + seconds / 3600


# --- WGS84 in metres ---------------------------------------------------------------------

@pytest.mark.parametrize("latitude_deg", [0.0, 45.0, -62.5])
def test_small_steps_of_latitude_and_longitude_are_the_ellipsoids_radii(latitude_deg):
    e2 = WGS84_F * (2 - WGS84_F)
    s2 = math.sin(math.radians(latitude_deg)) ** 2
    meridian_m = WGS84_A_M * (1 - e2) / (1 - e2 * s2) ** 1.5  # radius of curvature, N-S
    normal_m = WGS84_A_M / math.sqrt(1 - e2 * s2)  # E-W
    step = 0.001
    origin = LocalOrigin(latitude_deg, 10.0)
    en = east_north_m(np.array([latitude_deg - step / 2, latitude_deg + step / 2,
                                latitude_deg, latitude_deg]),
                      np.array([10.0, 10.0, 10.0 - step / 2, 10.0 + step / 2]), origin)
    north_m, east_m = en[1, 1] - en[0, 1], en[3, 0] - en[2, 0]
    assert north_m == pytest.approx(meridian_m * math.radians(step), rel=1e-7)
    assert east_m == pytest.approx(normal_m * math.cos(math.radians(latitude_deg))
                                   * math.radians(step), rel=1e-7)
    if latitude_deg == 45.0:
        assert north_m == pytest.approx(111.13, rel=1e-3)  # the textbook ~111 km a degree
    back = wgs84_from_east_north(en, origin)
    assert np.abs(back[:, 0] - [latitude_deg - step / 2, latitude_deg + step / 2,
                                latitude_deg, latitude_deg]).max() < 1e-12


# --- the plane similarity ----------------------------------------------------------------

def _orbit_xy(n: int, radius: float) -> np.ndarray:
    angles = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.column_stack([radius * np.cos(angles), radius * np.sin(angles) + 0.3 * angles])


def _circle_xy(n: int, radius: float) -> np.ndarray:
    """(n, 2) points on a circle: their RMS spread about the mean is ``radius``."""
    angles = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return radius * np.column_stack([np.cos(angles), np.sin(angles)])


def test_the_plane_similarity_is_exact():
    truth = PlaneSimilarity(3.7, 0.8, np.array([-12.0, 40.0]))
    source = np.random.default_rng(0).uniform(-5, 5, (9, 2))
    fitted = similarity_2d(source, truth.apply(source))
    assert fitted.scale == pytest.approx(truth.scale, rel=EXACT)
    assert fitted.heading_rad == pytest.approx(truth.heading_rad, abs=EXACT)
    assert np.abs(fitted.translation_m - truth.translation_m).max() < EXACT


def test_the_gps_fit_leaves_out_a_bad_fix_and_stays_exact():
    truth = PlaneSimilarity(2.5, -2.1, np.array([3.0, -7.0]))
    source = _orbit_xy(10, 12.0)  # 30 m in GPS metres: spread over the minimum
    target = truth.apply(source)
    target[4] += [40.0, -35.0]  # a stale fix, 53 m off
    fit = fit_gps(source, target)
    assert fit.similarity.scale == pytest.approx(truth.scale, rel=EXACT)
    assert fit.similarity.heading_rad == pytest.approx(truth.heading_rad, abs=EXACT)
    assert list(np.flatnonzero(~fit.kept)) == [4]
    assert fit.residuals_m[4] == pytest.approx(math.hypot(40, 35), rel=1e-9)
    assert np.delete(fit.residuals_m, 4).max() < 1e-9


@pytest.mark.parametrize(("source", "target", "message"), [
    (_orbit_xy(2, 10.0), _orbit_xy(2, 30.0), "2 of 2 photos carry an EXIF GPS position"),
    (_orbit_xy(8, 1.0), _circle_xy(8, MIN_SPREAD_M * 0.9), r"spread 18\.0 m .* under the 20 m"),
    (_orbit_xy(6, 1.0), np.random.default_rng(1).uniform(-500, 500, (6, 2)),
     r"only 2 of 6 GPS positions agree .* within 15 m"),
])
def test_too_few_fixes_too_close_or_disagreeing_are_refused(source, target, message):
    with pytest.raises(ValueError, match=message):
        fit_gps(source, target)


# --- the metric frame --------------------------------------------------------------------


def test_gps_gives_metres_and_true_north_even_with_a_bad_or_missing_fix():
    truth = true_poses()  # +y north: the cameras' GPS positions are their x (east), y
    names = [f"p{i}.jpg" for i in range(len(truth))]
    fixes = [fix_at(p[:2, 3]) for p in truth]
    fixes[2] = None  # no fix
    fixes[5] = fix_at(truth[5, :2, 3] + [0.0, 45.0])  # a bad one
    moved = np.stack([moved_pose(p) for p in truth])
    similarity, record = metric_similarity(moved, names, None, ScaleHint(gps=True), fixes)
    assert similarity.scale == pytest.approx(1 / SHRINK, rel=1e-9)
    out = np.stack([similarity.pose(p) for p in moved])
    # The true cameras, not turned: +y is north; only shifted (no points: input origin).
    assert np.abs(out[:, :3, :3] - truth[:, :3, :3]).max() < 1e-9
    shift = out[0, :3, 3] - truth[0, :3, 3]
    assert np.abs(out[:, :3, 3] - truth[:, :3, 3] - shift).max() < 1e-6
    assert record["scale_source"] == "gps" and record["north_known"] is True
    assert record["north_deg"] == 0.0
    gps = record["gps"]
    assert (gps["posed_photos_with_fix"], gps["fixes_kept"]) == (7, 6)
    assert list(gps["fixes_left_out"]) == ["p5.jpg"]
    assert gps["fixes_left_out"]["p5.jpg"] == pytest.approx(45.0, abs=1e-3)
    assert gps["residual_max_m"] < 1e-6
    # The world's origin is where the true world's input origin lies, in WGS84.
    origin_true_m = np.linalg.solve(TURN, -SHIFT)[:2] / SHRINK
    assert np.abs(fix_at(origin_true_m).latitude_deg - gps["origin_latitude_deg"]) < 1e-8


def test_the_compass_is_only_compared():
    truth = true_poses()
    forward = -truth[:, :3, 2]
    headings = np.degrees(np.arctan2(forward[:, 0], forward[:, 1])) % 360
    fixes = [GpsFix(f.latitude_deg, f.longitude_deg, None, float(h + 10.0), "M")
             for f, h in zip((fix_at(p[:2, 3]) for p in truth), headings)]
    similarity, record = metric_similarity(np.stack([moved_pose(p) for p in truth]),
                                           [f"p{i}" for i in range(8)], None,
                                           ScaleHint(gps=True), fixes)
    assert np.abs(similarity.rotation @ TURN - np.eye(3)).max() < 1e-9  # the compass: unused
    assert record["gps"]["compass"]["median_abs_difference_deg"] == pytest.approx(10.0)
    assert record["gps"]["compass"]["reference"] == ["M"]


def test_one_scale_only():
    with pytest.raises(ValueError, match="give one scale, not 2"):
        ScaleHint(known_height_m=9.0, gps=True)
