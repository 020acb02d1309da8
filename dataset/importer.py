"""``python -m dataset.importer FILE SCENE_DIR``: a building file's truth without rendering.

A thin alias of ``python -m dataset.generate``'s import path: the same sources (a labelled
mesh or an IFC model, told apart by :func:`dataset.importers.source.pick_source`), the same
import options (:mod:`dataset.source_args`) and the same import
(:class:`dataset.importers.source.BuildingEntry`); it writes the building's ``mesh.ply`` and
``building.json`` instead of rendering a scene (docs/importing.md).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from dataset.importers.mesh.building_file import IFC_SOURCE, MESH_SOURCE
from dataset.importers.source import pick_source
from dataset.source_args import add_import_arguments, source_options
from envelope.cli_errors import add_debug_flag, check_output_folder, exit_cli, run_cli
from envelope.mesh import write_labelled_ply
from envelope.truth import write_building

BUILDING_FILES = (MESH_SOURCE, IFC_SOURCE)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m dataset.importer",
        description="Import your own building file without rendering it: derive its ground "
        "truth (facades, window/wall/door areas seen from outside, WWR, footprint) and write "
        "building.json and mesh.ply (with facade ids) into a scene folder. The file is a "
        "labelled mesh (closed bodies, which may touch or overlap; label faces with a PLY "
        "'label' property: 0 background, 1 wall, 2 window, 3 roof, 4 door, 5 other, or name "
        "OBJ/GLB objects, groups or materials after the classes) or an IFC model. "
        "`python -m dataset.generate --mesh/--ifc FILE` imports it the same way and renders it.",
    )
    parser.add_argument("file", type=Path,
                        help="labelled mesh (.ply, .obj, .glb, .gltf) or IFC model (.ifc)")
    parser.add_argument("scene_dir", type=Path, help="folder to write building.json and mesh.ply")
    parser.add_argument("--id", dest="building_id", help="building id (default: file name)")
    add_import_arguments(parser)
    add_debug_flag(parser)
    args = parser.parse_args(argv)

    def body() -> int:
        source = pick_source(BUILDING_FILES, args.file) if args.file.is_file() else MESH_SOURCE
        (entry,) = source.read(args.file, source_options(source, args,
                                                         building_id=args.building_id))
        check_output_folder(args.scene_dir, "scene_dir")
        building = entry.build()
        write_labelled_ply(args.scene_dir / "mesh.ply", building.mesh)
        write_building(args.scene_dir / "building.json", building.truth)  # last: marks done
        t = building.truth
        print(f"{t.id}: {len(t.facades)} facades, facade {t.facade_area_m2:.2f} m2, window "
              f"{t.window_area_m2:.2f} m2, WWR {t.wwr:.4f}, footprint "
              f"{t.footprint_area_m2:.2f} m2 -> {args.scene_dir}")
        return 0

    return run_cli("dataset.importer", body, debug=args.debug)


if __name__ == "__main__":
    exit_cli(main())
