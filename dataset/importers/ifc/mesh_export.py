"""An IFC model -> a labelled mesh file, as BIM tools export one: one body per element.

Every element is triangulated by IfcOpenShell's geometry iterator in world coordinates,
openings subtracted, in metres (:func:`dataset.importers.ifc.convert.read_ifc`, the IFC
import's own reading) and written with its own vertices, nothing repaired or merged:
walls, slabs, roofs, windows, doors, interior walls, stairs and railings alike, each
labelled with the project's class of its entity (:mod:`dataset.importers.ifc.classes`).
Two layouts the mesh importer reads (docs/importing.md, section 1):

- ``.ply``: binary, a face ``label`` (class id) and ``facade`` (0) per face
  (:func:`envelope.mesh.write_labelled_ply`);
- ``.obj``: one object per element, ``o IfcWall_<GlobalId>``, its faces under
  ``usemtl wall`` (the class name; the object's name names no class, so the material
  does), coordinates written exactly (the shortest decimals that read back to the same
  float64).

The file has no storeys: import it with ``--ground-z`` at the model's ground, which
:func:`export_ifc_mesh` returns and the command prints.

    python -m dataset.importers.ifc.mesh_export house.ifc house.obj [--ifc-classes map.json]
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from dataset.importers.ifc.classes import read_class_overrides
from dataset.importers.ifc.convert import IfcModel, read_ifc
from envelope.atomic import write_text_atomic
from envelope.classes import CLASS_NAMES
from envelope.mesh import write_labelled_ply

SUFFIXES = (".ply", ".obj")


@dataclass(frozen=True)
class MeshExport:
    """What :func:`export_ifc_mesh` wrote.

    Attributes
    ----------
    path : Path
    elements : int
        Elements written (one body each).
    faces : int
    ground_z_m : float or None
        The model's ground (:mod:`dataset.importers.ifc.ground`) in the file's frame, to
        import it with; None for a model without storeys.
    """

    path: Path
    elements: int
    faces: int
    ground_z_m: float | None


def export_ifc_mesh(ifc_path: str | Path, out_path: str | Path, *,
                    overrides: dict | None = None, progress: bool = False) -> MeshExport:
    """Write the IFC model's elements as a labelled ``.ply`` or ``.obj`` (module docstring).

    Raises
    ------
    ValueError
        An unsupported suffix, or as :func:`dataset.importers.ifc.convert.read_ifc`.
    """
    out_path = Path(out_path)
    if out_path.suffix.lower() not in SUFFIXES:
        raise ValueError(f"{out_path}: write .ply or .obj, not {out_path.suffix!r}")
    model = read_ifc(ifc_path, overrides=overrides, progress=progress)
    return write_model_mesh(model, out_path)


def write_model_mesh(model: IfcModel, out_path: str | Path) -> MeshExport:
    """Write a triangulated IFC model (:func:`read_ifc`) as a labelled ``.ply`` or ``.obj``."""
    out_path = Path(out_path)
    if out_path.suffix.lower() == ".ply":
        write_labelled_ply(out_path, model.mesh)
    elif out_path.suffix.lower() == ".obj":
        write_text_atomic(out_path, obj_text(model))
    else:
        raise ValueError(f"{out_path}: write .ply or .obj, not {out_path.suffix!r}")
    return MeshExport(out_path, len(model.elements), len(model.mesh.faces),
                      None if model.ground is None else model.ground.z_m)


def obj_text(model: IfcModel) -> str:
    """The model as OBJ text: per element an object named ``<IfcType>_<GlobalId>``, its own
    vertices and its faces under ``usemtl <class name>``."""
    mesh = model.mesh
    lines = ["# one object per IFC element; usemtl names the class (docs/importing.md)"]
    n_written = 0
    for index, element in enumerate(model.elements):
        faces = mesh.faces[model.face_element == index]
        used, local = np.unique(faces, return_inverse=True)
        lines.append(f"o {element.ifc_type}_{element.global_id}")
        lines.extend("v {} {} {}".format(*p) for p in mesh.vertices_m[used].tolist())
        lines.append(f"usemtl {CLASS_NAMES[int(element.label)]}")
        corners = local.reshape(-1, 3) + 1 + n_written
        lines.extend(f"f {a} {b} {c}" for a, b, c in corners)
        n_written += len(used)
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m dataset.importers.ifc.mesh_export",
        description="Write an IFC model as a labelled mesh, one body per element "
                    "(docs/importing.md, section 2).")
    parser.add_argument("ifc", type=Path, help="the .ifc file")
    parser.add_argument("out", type=Path, help="the mesh to write: .ply or .obj")
    parser.add_argument("--ifc-classes", type=Path, default=None,
                        help="JSON mapping of entities or GlobalIds to classes, as for --ifc")
    args = parser.parse_args(argv)
    try:
        overrides = None if args.ifc_classes is None else read_class_overrides(args.ifc_classes)
        written = export_ifc_mesh(args.ifc, args.out, overrides=overrides, progress=True)
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    ground = ("no storey: give --ground-z yourself" if written.ground_z_m is None
              else f"import with --ground-z {written.ground_z_m:.6g}")
    print(f"{written.path}: {written.elements} elements, {written.faces} faces; {ground}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
