"""envelope.resources: estimates compared with given memory/disk figures (closed form)."""

import pytest

from envelope.resources import (
    RENDER_BYTES_PER_RAY,
    available_memory_bytes,
    check_disk,
    check_memory,
    format_bytes,
    free_disk_bytes,
)


def test_format_bytes():
    assert format_bytes(512) == "512 B"
    assert format_bytes(1536) == "1.5 KiB"
    assert format_bytes(3 * 2**40) == "3.0 TiB"


def test_memory_refused_above_nine_tenths_of_what_is_available():
    check_memory(0.9 * 1000, "x", "y", available=1000)  # exactly at the limit: allowed
    with pytest.raises(ValueError, match="x needs about 901 B of memory but 1000 B is "
                                         "available; y"):
        check_memory(901, "x", "y", available=1000)


def test_render_estimate_of_the_issue_case():
    """--resolution 100000: 1e10 rays of 400 B = 3.6 TiB, refused on any machine here."""
    assert RENDER_BYTES_PER_RAY * 1e10 / 2**40 == pytest.approx(3.64, abs=0.01)


def test_disk_refused_above_free_space(tmp_path):
    check_disk(10, tmp_path / "new" / "deep", "x", "y", free=10)
    with pytest.raises(ValueError, match="of disk in .* but 10 B is free"):
        check_disk(11, tmp_path, "x", "y", free=10)


def test_the_machine_figures_are_read():
    assert available_memory_bytes() > 0
    assert free_disk_bytes("/nonexistent/folder") > 0  # its nearest existing parent: /
