"""Packing a folder into bytes: exact round trip, equal folders give equal bytes, no escapes."""

import io
import tarfile

import pytest

from envelope.executors.folder_pack import pack_folder, unpack_folder


def _make_folder(root):
    (root / "images").mkdir(parents=True)
    (root / "images" / "a.png").write_bytes(bytes(range(256)) * 3)
    (root / "transforms.json").write_text('{"frames": []}\n')
    (root / "empty").mkdir()
    return root


def _tree(root):
    return {p.relative_to(root).as_posix(): (p.read_bytes() if p.is_file() else None)
            for p in root.rglob("*")}


def test_round_trip_restores_every_file_and_folder(tmp_path):
    src = _make_folder(tmp_path / "src")
    out = unpack_folder(pack_folder(src), tmp_path / "dst" / "scene")
    assert out == tmp_path / "dst" / "scene"
    assert _tree(out) == _tree(src)


def test_equal_folders_pack_to_equal_bytes(tmp_path):
    a = _make_folder(tmp_path / "a")
    b = _make_folder(tmp_path / "b")
    (b / "transforms.json").touch()  # another modification time, same content
    assert pack_folder(a) == pack_folder(b)


def test_refuses_a_missing_folder_and_members_outside_the_destination(tmp_path):
    with pytest.raises(ValueError, match="not a folder"):
        pack_folder(tmp_path / "missing")
    buf = io.BytesIO()
    with tarfile.open(fileobj=buf, mode="w") as tar:
        info = tarfile.TarInfo("../escaped.txt")
        info.size = 1
        tar.addfile(info, io.BytesIO(b"x"))
    with pytest.raises(ValueError, match="refusing to unpack"):
        unpack_folder(buf.getvalue(), tmp_path / "dst")
    assert not (tmp_path / "escaped.txt").exists()
