"""dataset.importers.photos with ``--gps``: EXIF GPS tags read in closed form (and a real
phone photo's), WGS84 in local metres against the ellipsoid's radii, the plane similarity
exact and robust to a bad fix, the metric frame with +y true north, each refusal with
nothing written, and (slow) structure from motion of a textured block whose photos carry
noisy GPS positions."""

from __future__ import annotations

import json
import math
import re
from fractions import Fraction

import cv2
import numpy as np
import pytest
from paths import REPO_ROOT
from PIL import ExifTags, Image
from PIL.TiffImagePlugin import IFDRational
from scipy.spatial.transform import Rotation

from dataset.generate import main as generate_main
from dataset.importers.photos.conventions import cam_from_world_cv
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
    OUTLIER_M,
    PlaneSimilarity,
    fit_gps,
    similarity_2d,
)
from dataset.importers.photos.metric_frame import ScaleHint, metric_similarity
from envelope.camera import Intrinsics, look_at
from envelope.scenes.scene import read_method_input

EXACT = 1e-9
FIXTURE = REPO_ROOT / "tests" / "fixtures" / "photos_gps" / "IMG_20180725_163423-128px.jpg"
WGS84_A_M = 6378137.0
WGS84_F = 1 / 298.257223563
ORIGIN = LocalOrigin(48.8583701, 2.2944813)
"""Where the synthetic photos are taken (degrees, WGS84)."""
K = Intrinsics(90.0, 90.0, 48.0, 32.0, 96, 64)
TURN = Rotation.from_euler("xyz", [30, -50, 110], degrees=True).as_matrix()
SHRINK = 0.25
SHIFT = np.array([1.0, -2.0, 0.5])
G = ExifTags.GPS


def _dms(value_deg: float) -> tuple[IFDRational, IFDRational, IFDRational]:
    """EXIF degrees, minutes, seconds of ``abs(value_deg)`` (seconds as a fine fraction)."""
    exact = Fraction(abs(value_deg))
    degrees = int(exact)
    minutes = int((exact - degrees) * 60)
    seconds = ((exact - degrees) * 60 - minutes) * 60
    return (IFDRational(degrees), IFDRational(minutes),
            IFDRational(seconds.limit_denominator(10 ** 6)))


def _gps_exif(latitude_deg: float, longitude_deg: float, **extra) -> Image.Exif:
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


def _fix_at(east_north: np.ndarray) -> GpsFix:
    latitude, longitude = wgs84_from_east_north(east_north, ORIGIN)[0]
    return GpsFix(float(latitude), float(longitude))


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
    Image.new("RGB", (16, 16)).save(path, exif=_gps_exif(-33.8567844, 151.2152967,
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

def _true_poses(n: int = 8, radius_m: float = 25.0) -> np.ndarray:
    return np.stack([look_at([radius_m * np.cos(a), radius_m * np.sin(a), 1.5 + (i % 3)],
                             [0, 0, 3]) for i, a in
                     enumerate(np.linspace(0, 2 * np.pi, n, endpoint=False))])


def _moved(pose: np.ndarray) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = TURN @ pose[:3, :3]
    out[:3, 3] = SHRINK * TURN @ pose[:3, 3] + SHIFT
    return out


def test_gps_gives_metres_and_true_north_even_with_a_bad_or_missing_fix():
    truth = _true_poses()  # +y north: the cameras' GPS positions are their x (east), y
    names = [f"p{i}.jpg" for i in range(len(truth))]
    fixes = [_fix_at(p[:2, 3]) for p in truth]
    fixes[2] = None  # no fix
    fixes[5] = _fix_at(truth[5, :2, 3] + [0.0, 45.0])  # a bad one
    moved = np.stack([_moved(p) for p in truth])
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
    assert np.abs(_fix_at(origin_true_m).latitude_deg - gps["origin_latitude_deg"]) < 1e-8


def test_the_compass_is_only_compared():
    truth = _true_poses()
    forward = -truth[:, :3, 2]
    headings = np.degrees(np.arctan2(forward[:, 0], forward[:, 1])) % 360
    fixes = [GpsFix(f.latitude_deg, f.longitude_deg, None, float(h + 10.0), "M")
             for f, h in zip((_fix_at(p[:2, 3]) for p in truth), headings)]
    similarity, record = metric_similarity(np.stack([_moved(p) for p in truth]),
                                           [f"p{i}" for i in range(8)], None,
                                           ScaleHint(gps=True), fixes)
    assert np.abs(similarity.rotation @ TURN - np.eye(3)).max() < 1e-9  # the compass: unused
    assert record["gps"]["compass"]["median_abs_difference_deg"] == pytest.approx(10.0)
    assert record["gps"]["compass"]["reference"] == ["M"]


def test_one_scale_only():
    with pytest.raises(ValueError, match="give one scale, not 2"):
        ScaleHint(known_height_m=9.0, gps=True)


# --- end to end --------------------------------------------------------------------------

def _colmap_project_with_gps(root, truth: np.ndarray, fixes: list[tuple[float, float] | None]):
    """A COLMAP text project of ``truth`` moved by TURN, SHRINK and SHIFT, its images
    carrying the given GPS positions (latitude, longitude; ``None``: no GPS)."""
    (root / "sparse" / "0").mkdir(parents=True)
    (root / "images").mkdir()
    images = []
    for i, pose in enumerate(truth):
        cv = cam_from_world_cv(_moved(pose))
        x, y, z, w = Rotation.from_matrix(cv[:3, :3]).as_quat()
        images += [f"{i + 1} {w} {x} {y} {z} {' '.join(map(str, cv[:, 3]))} 1 p{i}.jpg", ""]
        rgb = np.random.default_rng(i).integers(0, 255, (K.height, K.width, 3), np.uint8)
        exif = _gps_exif(*fixes[i]) if fixes[i] is not None else None
        Image.fromarray(rgb).save(root / "images" / f"p{i}.jpg",
                                  **({"exif": exif} if exif is not None else {}))
    rng = np.random.default_rng(0)
    points = np.column_stack([rng.uniform(-5, 5, 500), rng.uniform(-4, 4, 500),
                              np.linspace(0.0, 9.0, 500)])
    (root / "sparse" / "0" / "cameras.txt").write_text(
        f"1 PINHOLE {K.width} {K.height} {K.fx} {K.fy} {K.cx} {K.cy}\n")
    (root / "sparse" / "0" / "images.txt").write_text("\n".join(images) + "\n")
    (root / "sparse" / "0" / "points3D.txt").write_text("".join(
        f"{j + 1} {p[0]} {p[1]} {p[2]} 128 128 128 0.5\n"
        for j, p in enumerate(SHRINK * points @ TURN.T + SHIFT)))


def test_a_colmap_project_with_gps_photos_comes_out_north_up(tmp_path, capsys):
    truth = _true_poses()
    fixes = [tuple(wgs84_from_east_north(p[:2, 3], ORIGIN)[0]) for p in truth]
    _colmap_project_with_gps(tmp_path / "survey", truth, fixes)
    code = generate_main(["--photos", str(tmp_path / "survey"), "--out", str(tmp_path / "out"),
                          "--gps", "--quiet"])
    assert code == 0, capsys.readouterr().err
    scene = read_method_input(tmp_path / "out" / "survey")
    out = np.stack([f.world_from_camera for f in scene.frames])
    assert np.abs(out[:, :3, :3] - truth[:, :3, :3]).max() < 1e-6  # +y north, x east
    shift = out[0, :3, 3] - truth[0, :3, 3]
    assert np.abs(out[:, :3, 3] - truth[:, :3, 3] - shift).max() < 1e-5
    record = json.loads((tmp_path / "out" / "survey" / "transforms.json").read_text())["photos"]
    assert record["scale_source"] == "gps" and record["north_known"] is True
    assert record["gps"]["fixes_kept"] == 8 and record["gps"]["residual_max_m"] < 1e-5


def test_a_colmap_project_with_too_few_fixes_is_refused_and_leaves_no_scene(tmp_path, capsys):
    truth = _true_poses()
    fixes = [tuple(wgs84_from_east_north(p[:2, 3], ORIGIN)[0]) if i < 2 else None
             for i, p in enumerate(truth)]
    _colmap_project_with_gps(tmp_path / "survey", truth, fixes)
    code = generate_main(["--photos", str(tmp_path / "survey"), "--out", str(tmp_path / "out"),
                          "--gps", "--quiet"])
    err = capsys.readouterr().err
    assert code == 2 and "--gps: 2 of 8 photos carry an EXIF GPS position" in err
    assert len(err.strip().splitlines()) == 1
    assert list((tmp_path / "out").iterdir()) == []


def _noise_photos(folder, positions_m: list[np.ndarray | None]) -> None:
    folder.mkdir()
    for i, position in enumerate(positions_m):
        rgb = np.random.default_rng(i).integers(0, 255, (60, 80, 3), np.uint8)
        exif = (_gps_exif(*wgs84_from_east_north(position, ORIGIN)[0])
                if position is not None else None)
        Image.fromarray(rgb).save(folder / f"p{i}.jpg",
                                  **({"exif": exif} if exif is not None else {}))


@pytest.mark.parametrize(("positions_m", "message"), [
    ([np.array([0.0, 0.0]), np.array([30.0, 0.0]), None, None],
     "--gps: 2 of 4 photos carry an EXIF GPS position; at least 3"),
    ([np.array([0.0, 0.0]), np.array([10.0, 0.0]), np.array([0.0, 10.0])],
     r"--gps: the photos' GPS positions spread 6\.7 m"),  # RMS about the mean: 20 / 3 m
])
def test_a_photo_folder_without_usable_gps_is_refused_before_anything_runs(
        tmp_path, capsys, positions_m, message):
    _noise_photos(tmp_path / "photos", positions_m)
    code = generate_main(["--photos", str(tmp_path / "photos"), "--out", str(tmp_path / "out"),
                          "--gps", "--quiet"])
    err = capsys.readouterr().err
    assert code == 2 and re.search(message, err), err
    assert len(err.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()


def test_gps_goes_with_photos_and_alone(tmp_path, capsys):
    code = generate_main(["--preset", "tiny", "--out", str(tmp_path / "out"), "--gps"])
    assert code == 2 and "go with --photos" in capsys.readouterr().err
    _noise_photos(tmp_path / "photos", [np.zeros(2)] * 3)
    code = generate_main(["--photos", str(tmp_path / "photos"), "--out", str(tmp_path / "out"),
                          "--gps", "--known-height", "9", "--quiet"])
    assert code == 2 and "give one scale, not 2" in capsys.readouterr().err


# --- slow: structure from motion ---------------------------------------------------------

GPS_NOISE_M = 1.5
"""Each synthetic fix's error (per axis, independent): a good receiver in the open."""
# Measured (2026-11-29, pycolmap 4.2.1, two runs): against the true cameras, scale 0.9869 and
# heading 1.453 deg (what 1.5 m of GPS noise allows: about 1.5 / (22 m x sqrt(19)) = 1.6 %);
# against the same fit of the true cameras' centres (a perfect structure from motion),
# -3.8e-5 and under 0.0005 deg. The tolerances leave room for another machine's floating
# point.
SFM_SCALE_TOLERANCE = 2e-3
SFM_HEADING_TOLERANCE_DEG = 0.2
GPS_SCALE_TOLERANCE = 0.05
GPS_HEADING_TOLERANCE_DEG = 4.0


@pytest.mark.slow
def test_photos_of_a_textured_block_with_noisy_gps_come_out_in_metres_north_up(tmp_path,
                                                                             capsys):
    from test_photos_sfm import write_block_photos

    from dataset.importers.photos.pose_error import similarity_alignment

    truth = write_block_photos(tmp_path / "png")
    noise = np.random.default_rng(5).normal(0.0, GPS_NOISE_M, (len(truth), 2))
    gps_m = {}
    (tmp_path / "block").mkdir()
    for i, (name, (pose, _)) in enumerate(sorted(truth.items())):
        gps_m[name] = pose[:2, 3] + noise[i] + ([35.0, 20.0] if i == 7 else 0.0)  # one bad
        rgb = cv2.cvtColor(cv2.imread(str(tmp_path / "png" / name)), cv2.COLOR_BGR2RGB)
        Image.fromarray(rgb).save(tmp_path / "block" / name.replace(".png", ".jpg"),
                                  quality=95, exif=_gps_exif(
                                      *wgs84_from_east_north(gps_m[name], ORIGIN)[0]))
    code = generate_main(["--photos", str(tmp_path / "block"), "--out", str(tmp_path / "out"),
                          "--gps", "--quiet"])
    assert code == 0, capsys.readouterr().err
    scene = read_method_input(tmp_path / "out" / "block")
    record = json.loads((tmp_path / "out" / "block" / "transforms.json").read_text())["photos"]
    assert list(record["gps"]["fixes_left_out"]) == ["v07.jpg"]
    assert record["gps"]["fixes_left_out"]["v07.jpg"] > OUTLIER_M
    assert record["gps"]["residual_median_m"] < 3 * GPS_NOISE_M
    names = [f.file_path.removeprefix("images/").replace(".jpg", ".png") for f in scene.frames]
    posed = np.stack([f.world_from_camera for f in scene.frames])
    true = np.stack([truth[n][0] for n in names])
    scale, rotation, _shift = similarity_alignment(posed[:, :3, 3], true[:, :3, 3])
    heading_deg = math.degrees(math.atan2(rotation[1, 0], rotation[0, 0]))
    assert np.degrees(np.arccos(rotation[2, 2])) < 0.2  # z up
    # Metres and north as far as the GPS noise allows...
    assert abs(scale - 1) < GPS_SCALE_TOLERANCE
    assert abs(heading_deg) < GPS_HEADING_TOLERANCE_DEG
    # ... and as a perfect structure from motion would give them: the same fit of the true
    # centres onto the same fixes (the bad one left out).
    kept = [n for n in names if n != "v07.png"]
    perfect = similarity_2d(np.stack([truth[n][0][:2, 3] for n in kept]),
                            np.stack([gps_m[n] for n in kept]))
    assert abs(scale * perfect.scale - 1) < SFM_SCALE_TOLERANCE
    assert abs(heading_deg + math.degrees(perfect.heading_rad)) < SFM_HEADING_TOLERANCE_DEG
    print(f"scale {scale:.5f}, heading {heading_deg:.3f} deg; against the perfect fit "
          f"{scale * perfect.scale - 1:.2e}, "
          f"{heading_deg + math.degrees(perfect.heading_rad):.3f} deg")
