"""Bad photos through the segmenter's image-reading path: a result or a clear error.

Every image is made here with Pillow: grey, 1x1, 16-bit, CMYK, EXIF-rotated, truncated,
floating-point. Each goes through :func:`segment.segmenter.segment_photo` (the path of
``python -m segment.predict --photos``) with the committed weights.
"""

import numpy as np
import pytest
from PIL import Image

from envelope.classes import NUM_CLASSES
from envelope.photo_io import read_photo_rgb
from segment.predict import main
from segment.segmenter import network_segmenter, segment_photo
from segment.weights import DEFAULT_WEIGHTS

EXIF_ORIENTATION = 0x0112
ROTATED_90_CW = 6
"""EXIF orientation 6: the stored image must be turned 90 degrees clockwise to view it."""


@pytest.fixture(scope="module")
def segmenter():
    return network_segmenter(DEFAULT_WEIGHTS, threads=1)


def _check_labels(labels: np.ndarray, shape: tuple[int, int]) -> None:
    assert labels.shape == shape and labels.dtype == np.uint8
    assert int(labels.max()) < NUM_CLASSES


def test_grey_image_becomes_three_equal_channels(tmp_path, segmenter):
    grey = np.tile(np.arange(0, 240, 8, dtype=np.uint8), (20, 1))  # (20, 30) ramp
    Image.fromarray(grey).save(tmp_path / "grey.png")
    rgb = read_photo_rgb(tmp_path / "grey.png")
    assert rgb.shape == (20, 30, 3) and rgb.dtype == np.uint8
    for k in range(3):
        np.testing.assert_array_equal(rgb[..., k], grey)
    _check_labels(segment_photo(segmenter, tmp_path / "grey.png"), (20, 30))


def test_one_pixel_image_gets_one_label(tmp_path, segmenter):
    Image.new("RGB", (1, 1), (120, 130, 140)).save(tmp_path / "one.png")
    np.testing.assert_array_equal(read_photo_rgb(tmp_path / "one.png"), [[[120, 130, 140]]])
    _check_labels(segment_photo(segmenter, tmp_path / "one.png"), (1, 1))


def test_sixteen_bit_png_is_scaled_not_clipped(tmp_path, segmenter):
    values = np.array([[0, 257 * 100, 65535, 32896]], dtype=np.uint16).repeat(4, axis=0)
    Image.fromarray(values).save(tmp_path / "deep.png")
    with Image.open(tmp_path / "deep.png") as img:
        assert img.mode.startswith("I")  # stored as 16-bit grey
    rgb = read_photo_rgb(tmp_path / "deep.png")
    # v * 255 / 65535 rounded: exact for 0, 257k and 65535; 32896 -> 128.
    np.testing.assert_array_equal(rgb[0, :, 0], [0, 100, 255, 128])
    np.testing.assert_array_equal(rgb[..., 0], rgb[..., 2])
    _check_labels(segment_photo(segmenter, tmp_path / "deep.png"), (4, 4))


def test_cmyk_jpeg_is_converted_to_rgb(tmp_path, segmenter):
    # Pure cyan-free magenta+yellow = red in CMYK (0, 255, 255, 0).
    Image.new("CMYK", (32, 24), (0, 255, 255, 0)).save(tmp_path / "cmyk.jpg", quality=95)
    with Image.open(tmp_path / "cmyk.jpg") as img:
        assert img.mode == "CMYK"
    rgb = read_photo_rgb(tmp_path / "cmyk.jpg")
    assert rgb.shape == (24, 32, 3)
    # Red within JPEG's error (a few levels on a flat colour).
    np.testing.assert_allclose(rgb.reshape(-1, 3).mean(axis=0), [255, 0, 0], atol=4)
    _check_labels(segment_photo(segmenter, tmp_path / "cmyk.jpg"), (24, 32))


def test_exif_orientation_is_applied(tmp_path, segmenter):
    stored = np.zeros((40, 60, 3), np.uint8)  # 60 wide, 40 high as stored
    stored[:20, :20] = (255, 0, 0)  # red block at the stored top-left
    img = Image.fromarray(stored)
    exif = img.getexif()
    exif[EXIF_ORIENTATION] = ROTATED_90_CW
    img.save(tmp_path / "sideways.jpg", exif=exif.tobytes(), quality=95)
    rgb = read_photo_rgb(tmp_path / "sideways.jpg")
    # Turned 90 degrees clockwise: 40 wide, 60 high, the stored top-left now top-right.
    assert rgb.shape == (60, 40, 3)
    assert rgb[5, 35, 0] > 200 and rgb[5, 35, 1] < 60  # red
    assert rgb[5, 5].max() < 60 and rgb[55, 35].max() < 60  # black
    _check_labels(segment_photo(segmenter, tmp_path / "sideways.jpg"), (60, 40))


def test_truncated_jpeg_is_a_clear_error(tmp_path, segmenter):
    rng = np.random.default_rng(0)
    Image.fromarray(rng.integers(0, 255, (64, 64, 3), dtype=np.uint8)).save(
        tmp_path / "whole.jpg", quality=90)
    data = (tmp_path / "whole.jpg").read_bytes()
    (tmp_path / "cut.jpg").write_bytes(data[: len(data) // 2])
    with pytest.raises(ValueError, match=r"cut\.jpg: truncated or corrupt image"):
        segment_photo(segmenter, tmp_path / "cut.jpg")
    (tmp_path / "noise.jpg").write_bytes(b"not a jpeg at all")
    with pytest.raises(ValueError, match=r"noise\.jpg: not an image Pillow can read"):
        read_photo_rgb(tmp_path / "noise.jpg")
    with pytest.raises(ValueError, match="no such image file"):
        read_photo_rgb(tmp_path / "absent.jpg")


def test_float_image_is_refused(tmp_path):
    Image.fromarray(np.full((4, 4), 0.5, np.float32)).save(tmp_path / "f.tif")
    with pytest.raises(ValueError, match="floating-point image has no fixed range"):
        read_photo_rgb(tmp_path / "f.tif")


def test_predict_photos_segments_the_good_and_names_the_bad(tmp_path, capsys):
    photos = tmp_path / "photos"
    photos.mkdir()
    Image.new("L", (24, 16), 90).save(photos / "grey.png")
    Image.new("CMYK", (16, 16), (0, 0, 0, 128)).save(photos / "cmyk.jpg")
    Image.new("RGB", (16, 16), (10, 20, 30)).save(photos / "whole.jpg")
    (photos / "cut.jpg").write_bytes((photos / "whole.jpg").read_bytes()[:200])
    (photos / "notes.txt").write_text("not a photo")
    out = tmp_path / "masks"
    assert main(["--photos", str(photos), "--out", str(out), "--threads", "1"]) == 1
    assert sorted(p.name for p in out.iterdir()) == ["cmyk.png", "grey.png", "whole.png"]
    with Image.open(out / "grey.png") as labels:
        assert labels.size == (24, 16) and labels.mode == "L"
    err = capsys.readouterr().err
    assert "skipped" in err and "cut.jpg" in err and "notes.txt" not in err
    assert main(["--photos", str(photos), "--out", str(photos)]) == 2
    assert "holds the photos themselves" in capsys.readouterr().err
