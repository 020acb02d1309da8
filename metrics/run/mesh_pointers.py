"""``<method>_runs.json``: where the meshes of a method that keeps one (``mesh_file``) are, per
scene and protocol.

:mod:`metrics.compare` writes one such file per method with a ``mesh_file``
(:class:`envelope.method.Method`) into its output folder; the HTML report and
``figures.make`` read them to draw each scene's semantic mesh
(:mod:`envelope.semantic_ply`).
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from envelope.atomic import write_json_atomic
from envelope.method import artefacts_folder
from envelope.protocols import TRAIN_PROTOCOL, Protocol
from metrics.run.runner import MethodSpec

SUFFIX = "_runs.json"


@dataclass(frozen=True)
class MeshRun:
    """One scene's mesh of one method, made from the views of ``protocol`` (absolute path)."""

    method: str
    scene: str
    protocol: Protocol
    mesh: Path


def write_mesh_pointers(scene_dirs: Sequence[Path], spec: MethodSpec, out_dir: Path) -> None:
    """``out_dir/<method>_runs.json``: each (scene, protocol of ``spec``) for which ``spec``
    keeps a mesh, with its run folder (:func:`envelope.method.artefacts_folder`), the mesh
    and the ``footprint.geojson`` beside it (``None`` if absent); nothing for a method
    without a mesh."""
    if spec.mesh_file is None or spec.artefacts_dir is None:
        return
    runs = []
    for scene_dir in scene_dirs:
        for protocol in spec.protocols:
            run_dir = artefacts_folder(spec.artefacts_dir, scene_dir.name, protocol)
            mesh = run_dir / spec.mesh_file
            if mesh.is_file():
                footprint = mesh.parent / "footprint.geojson"
                runs.append({
                    "scene": scene_dir.name,
                    "protocol": protocol,
                    "run_dir": str(run_dir.resolve()),
                    "mesh": str(mesh.resolve()),
                    "footprint": str(footprint.resolve()) if footprint.is_file() else None,
                })
    write_json_atomic(out_dir / f"{spec.name}{SUFFIX}", {"runs": runs})


def read_mesh_pointers(out_dir: Path) -> list[MeshRun]:
    """Every method's meshes listed in ``out_dir``, by method then in file order (a file
    written before runs named their protocol reads as the orbit's, which it was)."""
    found = []
    for path in sorted(out_dir.glob(f"*{SUFFIX}")):
        method = path.name[:-len(SUFFIX)]
        for run in json.loads(path.read_text()).get("runs", []):
            found.append(MeshRun(method, run["scene"], run.get("protocol", TRAIN_PROTOCOL),
                                 Path(run["mesh"])))
    return found
