"""``python -m dataset.importer MESH SCENE_DIR``: import a labelled building mesh as a scene.

The import itself is :func:`dataset.importers.mesh_import.import_labelled_mesh`
(docs/importing.md); this command writes its ``building.json`` and ``mesh.ply``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from dataset.core.cli_errors import add_debug_flag, check_output_folder, run_cli
from dataset.core.mesh import write_labelled_ply
from dataset.core.truth import write_building
from dataset.importers.import_config import add_import_arguments, import_config_from_args
from dataset.importers.mesh_import import import_labelled_mesh


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m dataset.importer",
        description="Import your own labelled building mesh: derive its ground truth (facades, "
        "window/wall/door areas seen from outside, WWR, footprint) and write building.json and "
        "mesh.ply (with facade ids) into a scene folder. The mesh is closed bodies (they may "
        "touch or overlap); label faces with a PLY 'label' property (0 background, 1 wall, "
        "2 window, 3 roof, 4 door, 5 other) or name OBJ/GLB objects, groups or materials after "
        "the classes.",
    )
    parser.add_argument("mesh", type=Path, help="labelled mesh: .ply, .obj, .glb or .gltf")
    parser.add_argument("scene_dir", type=Path, help="folder to write building.json and mesh.ply")
    parser.add_argument("--id", dest="building_id", help="building id (default: file name)")
    add_import_arguments(parser)
    add_debug_flag(parser)
    args = parser.parse_args(argv)

    def body() -> int:
        config = import_config_from_args(args)
        check_output_folder(args.scene_dir, "scene_dir")
        building = import_labelled_mesh(args.mesh, building_id=args.building_id, config=config)
        write_labelled_ply(args.scene_dir / "mesh.ply", building.mesh)
        write_building(args.scene_dir / "building.json", building.truth)  # last: marks done
        t = building.truth
        print(f"{t.id}: {len(t.facades)} facades, facade {t.facade_area_m2:.2f} m2, window "
              f"{t.window_area_m2:.2f} m2, WWR {t.wwr:.4f}, footprint "
              f"{t.footprint_area_m2:.2f} m2 -> {args.scene_dir}")
        return 0

    return run_cli("dataset.importer", body, debug=args.debug)


if __name__ == "__main__":
    sys.exit(main())
