"""Either official BuildNet3D layout in one call: ``dataset.generate --buildnet3d PATH``.

The BlenderProc generator's or dataparser's layout (:mod:`dataset.importers.blenderproc`)
is recognised by its ``meta_data.json``; anything else is read as the BuildNet3D-dataset
Blender generator's layout (:mod:`dataset.importers.buildnet3d`), whose finder raises a
``ValueError`` naming both layouts when ``path`` holds neither.
"""

from __future__ import annotations

from pathlib import Path

from dataset.importers.blenderproc import find_scenes, import_blenderproc
from dataset.importers.buildnet3d import import_buildnet3d


def import_official(path: str | Path, out_root: str | Path, *,
                    overwrite: bool = False) -> list[Path]:
    """Import every building under ``path`` (either official layout) into ``out_root``;
    return the scene folders. An existing scene is kept unless ``overwrite``.
    """
    if find_scenes(path):
        return import_blenderproc(path, out_root, overwrite=overwrite)
    return import_buildnet3d(path, out_root, overwrite=overwrite)
