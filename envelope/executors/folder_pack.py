"""A folder as one bytes object and back: how scenes and run folders travel between machines.

Executors without a shared file system (:mod:`envelope.executors.ray_tasks`) send a
scene folder to a worker and a method's run folder back to the driver as an
uncompressed tar archive (the images inside are PNGs, already compressed).
The archive holds paths relative to the folder, in sorted order, with fixed
owners and times, so equal folders pack to equal bytes.
"""

from __future__ import annotations

import io
import tarfile
from pathlib import Path


def pack_folder(folder: str | Path) -> bytes:
    """The files and sub-folders of ``folder`` as tar bytes (paths relative to ``folder``).

    Raises
    ------
    ValueError
        If ``folder`` is not a folder.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise ValueError(f"cannot pack {folder}: not a folder")
    buf = io.BytesIO()
    with tarfile.open(fileobj=buf, mode="w") as tar:
        for path in sorted(folder.rglob("*")):
            if not (path.is_file() or path.is_dir()) or path.is_symlink():
                continue
            info = tar.gettarinfo(str(path), arcname=path.relative_to(folder).as_posix())
            info.uid = info.gid = 0
            info.uname = info.gname = ""
            info.mtime = 0
            if info.isfile():
                with path.open("rb") as f:
                    tar.addfile(info, f)
            else:
                tar.addfile(info)
    return buf.getvalue()


def unpack_folder(data: bytes, dest: str | Path) -> Path:
    """Write the folder packed in ``data`` into ``dest`` (created if absent); return ``dest``.

    Members that would land outside ``dest`` (absolute paths, ``..``, links) are
    refused with ``ValueError``.
    """
    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    with tarfile.open(fileobj=io.BytesIO(data), mode="r") as tar:
        try:
            tar.extractall(dest, filter="data")
        except tarfile.FilterError as exc:
            raise ValueError(f"refusing to unpack into {dest}: {exc}") from exc
    return dest
