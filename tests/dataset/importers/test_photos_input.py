"""dataset.importers.photos: what a folder of photos may hold, and a clear error with nothing
written for each bad input (too few photos, a video, HEIC, a corrupt JPEG, no scale, photos
that do not overlap); photos of other sizes or cameras get their own intrinsics."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from PIL import ExifTags, Image

from dataset.generate import main as generate_main
from dataset.importers.photos.metric_frame import KnownDistance, ScaleHint
from dataset.importers.photos.photo_folder import camera_groups, list_photos
from dataset.importers.photos.source import PHOTOS_SOURCE, PhotosOptions
from dataset.importers.source import write_scenes

SCALE = ["--known-distance", "p0.png", "p1.png", "2"]


def _noise(path, width=160, height=120, seed=0, exif=None):
    """A photo of smooth random noise (SIFT finds features; two seeds share none)."""
    rng = np.random.default_rng(seed)
    grey = cv2.resize(rng.random((height // 4, width // 4)), (width, height),
                      interpolation=cv2.INTER_CUBIC)
    rgb = np.repeat((np.clip(grey, 0, 1) * 255).astype(np.uint8)[..., None], 3, axis=2)
    Image.fromarray(rgb).save(path, **({"exif": exif} if exif is not None else {}))
    return path


def _folder(tmp_path, n=3, name="photos"):
    folder = tmp_path / name
    folder.mkdir()
    for i in range(n):
        _noise(folder / f"p{i}.png", seed=i)
    return folder


def _generate(capsys, *args):
    code = generate_main([*map(str, args), "--quiet"])
    return code, capsys.readouterr().err


def test_photos_are_the_folders_jpeg_and_png_files_sorted(tmp_path):
    folder = _folder(tmp_path)
    (folder / "p1.xmp").write_text("sidecar")
    (folder / ".hidden.jpg").write_bytes(b"")
    (folder / "sub").mkdir()
    _noise(folder / "A.JPG")
    assert [p.name for p in list_photos(folder)] == ["A.JPG", "p0.png", "p1.png", "p2.png"]
    assert PHOTOS_SOURCE.detect(folder) and not PHOTOS_SOURCE.detect(folder / "sub")


def test_the_exif_orientation_and_focal_length_are_read(tmp_path):
    exif = Image.Exif()
    exif[ExifTags.Base.Orientation] = 6  # stored sideways: shown turned a quarter
    exif[ExifTags.Base.Make] = "Acme"
    exif.get_ifd(ExifTags.IFD.Exif)[ExifTags.Base.FocalLengthIn35mmFilm] = 27
    folder = _folder(tmp_path)
    _noise(folder / "turned.jpg", width=160, height=120, exif=exif)
    turned = [p for p in list_photos(folder) if p.name == "turned.jpg"][0]
    assert (turned.width, turned.height) == (120, 160)
    assert turned.focal_px == pytest.approx(27 / 36 * 160)


def test_photos_of_other_cameras_or_sizes_get_their_own_intrinsics(tmp_path):
    exif = Image.Exif()
    exif[ExifTags.Base.Make] = "Acme"
    folder = _folder(tmp_path)
    _noise(folder / "q0.png", width=200, height=100)
    _noise(folder / "q1.jpg", exif=exif)
    groups = camera_groups(list_photos(folder))
    assert [[p.name for p in g] for g in groups.values()] == [
        ["p0.png", "p1.png", "p2.png"], ["q0.png"], ["q1.jpg"]]


def test_too_few_photos_are_refused(tmp_path, capsys):
    folder = _folder(tmp_path, n=2)
    code, err = _generate(capsys, "--photos", folder, "--out", tmp_path / "out", *SCALE)
    assert code == 2 and "holds 2 photos" in err and "at least 3" in err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("name", ["walk.mp4", "walk.MOV"])
def test_a_video_is_refused_with_how_to_extract_frames(tmp_path, capsys, name):
    folder = _folder(tmp_path)
    (folder / name).write_bytes(b"\x00\x00\x00\x18ftypmp42")
    code, err = _generate(capsys, "--photos", folder, "--out", tmp_path / "out", *SCALE)
    assert code == 2 and "holds videos" in err and "ffmpeg" in err
    code, err = _generate(capsys, "--photos", folder / name, "--out", tmp_path / "out", *SCALE)
    assert code == 2 and "is a video" in err
    assert not (tmp_path / "out").exists()


def test_heic_photos_are_refused_with_the_fix(tmp_path, capsys):
    folder = _folder(tmp_path)
    (folder / "IMG_0001.HEIC").write_bytes(b"\x00\x00\x00\x18ftypheic")
    code, err = _generate(capsys, "--photos", folder, "--out", tmp_path / "out", *SCALE)
    assert code == 2 and "IMG_0001.HEIC" in err and "convert them to JPEG" in err


def test_no_scale_is_refused_before_anything_runs(tmp_path, capsys):
    folder = _folder(tmp_path)
    code, err = _generate(capsys, "--photos", folder, "--out", tmp_path / "out")
    assert code == 2 and ("--known-distance PHOTO_A PHOTO_B METRES, --known-height METRES, "
                          "--gps or --city-model FILE_OR_DIR") in err
    assert not (tmp_path / "out").exists()
    code, err = _generate(capsys, "--photos", folder, "--out", tmp_path / "out",
                          "--known-distance", "p0.png", "nowhere.png", "2")
    assert code == 2 and "nowhere.png, which is not a photo" in err
    code, err = _generate(capsys, "--preset", "tiny", "--out", tmp_path / "out",
                          "--known-height", "9")
    assert code == 2 and "go with --photos" in err


def test_a_corrupt_jpeg_stops_the_run_and_leaves_no_scene(tmp_path, capsys):
    folder = _folder(tmp_path)
    whole = _noise(tmp_path / "whole.jpg", seed=7)
    data = whole.read_bytes()
    (folder / "cut.jpg").write_bytes(data[: len(data) // 2])  # the header, half the scan
    code, err = _generate(capsys, "--photos", folder, "--out", tmp_path / "out", *SCALE)
    assert code == 2 and "cut.jpg: truncated or corrupt image" in err
    assert list((tmp_path / "out").iterdir()) == []
    (folder / "cut.jpg").write_bytes(b"not a jpeg at all")
    code, err = _generate(capsys, "--photos", folder, "--out", tmp_path / "out", *SCALE)
    assert code == 2 and "cut.jpg: not an image" in err


def test_photos_that_do_not_overlap_are_refused_and_leave_no_scene(tmp_path):
    folder = _folder(tmp_path)  # three unrelated noise images: nothing to match
    options = PhotosOptions(ScaleHint(KnownDistance("p0.png", "p1.png", 2.0)), progress=False)
    with pytest.raises(ValueError, match=r"placed 0 of 3 photos .* do not overlap enough"):
        write_scenes(PHOTOS_SOURCE.read(folder, options), tmp_path / "out", progress=False)
    assert list((tmp_path / "out").iterdir()) == []
