"""envelope.atomic: what it writes gets the mode the user's umask gives, and a failed
write leaves nothing behind."""

import os
import stat
from contextlib import contextmanager

import pytest

from envelope.atomic import atomic_directory, write_bytes_atomic, write_json_atomic


@contextmanager
def umask(mask):
    before = os.umask(mask)
    try:
        yield
    finally:
        os.umask(before)


def mode(path):
    return stat.S_IMODE(path.stat().st_mode)


@pytest.mark.parametrize("mask", [0o022, 0o077, 0o002], ids=oct)
def test_files_and_folders_get_the_umask_mode(tmp_path, mask):
    with umask(mask):
        write_json_atomic(tmp_path / "r.json", {"wwr": 0.3})
        write_bytes_atomic(tmp_path / "sub" / "b.bin", b"\x00\x01")
        with atomic_directory(tmp_path / "run") as folder:
            (folder / "x.txt").write_text("x")
    assert mode(tmp_path / "r.json") == 0o666 & ~mask
    assert mode(tmp_path / "sub" / "b.bin") == 0o666 & ~mask
    assert mode(tmp_path / "run") == 0o777 & ~mask
    assert (tmp_path / "r.json").read_text() == '{\n  "wwr": 0.3\n}\n'


def test_replacing_a_file_and_a_failed_write_leave_no_temporary(tmp_path):
    write_bytes_atomic(tmp_path / "a", b"old")
    write_bytes_atomic(tmp_path / "a", b"new")
    with pytest.raises(RuntimeError), atomic_directory(tmp_path / "run") as folder:
        (folder / "half").write_text("half")
        raise RuntimeError("crash")
    assert (tmp_path / "a").read_bytes() == b"new"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a"]
