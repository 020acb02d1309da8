"""A user's own labelled building mesh -> :class:`dataset.truth.Building` with derived truth.

Steps (docs/importing.md): read the file (:mod:`dataset.mesh_files`); check it is a
closed, consistently oriented mesh with facade classes; move it to the origin; find the
wall/window/door faces seen from outside (:mod:`dataset.visibility`, embree); group them
into facades (:mod:`dataset.facade_grouping`); sum areas per class and facade; cut the
footprint at ``footprint_height_m`` (:mod:`dataset.section`).
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from dataset.classes import FACADE_CLASSES, NO_FACADE, SemanticClass
from dataset.cli_errors import add_debug_flag, check_output_folder, run_cli
from dataset.facade_grouping import FacadeGroup, facade_ids_of_faces, group_facades
from dataset.footprint import polygon_to_geojson
from dataset.mesh import LabelledMesh, write_labelled_ply
from dataset.mesh_files import UpAxis, read_labelled_mesh_file
from dataset.section import cross_section_footprint
from dataset.truth import Building, BuildingTruth, FacadeTruth, write_building
from dataset.visibility import embree_intersector, escape_fractions
from dataset.wwr import gross_facade_area_m2, wwr_from_areas

CURVED_SPREAD_DEG = 1.0  # a facade whose face normals spread wider than this is curved


@dataclass(frozen=True)
class ImportConfig:
    """How a labelled mesh becomes a building; lengths in metres, angles in degrees."""

    up_axis: UpAxis = "z"
    """The file's up axis: glTF exported by Blender is y-up."""
    recentre: bool = True
    """Move the mesh so that its x/y bounding-box centre is at the origin and its lowest point
    at z = 0 (DESIGN.md's world); the shift is recorded in the truth's ``extra``."""
    max_tilt_deg: float = 10.0
    """Faces whose normal is further than this from horizontal (roof-like) are no facade."""
    angle_tolerance_deg: float = 10.0
    """Faces within this angle of a facade's direction join it (curved walls: sectors)."""
    offset_tolerance_m: float = 0.3
    """Parallel planes closer than this are one facade (windows set back into the wall)."""
    gap_tolerance_m: float = 0.05
    """Coplanar wall pieces further apart than this along the wall are different facades."""
    min_facade_width_m: float = 0.5
    """Narrower groups (window reveals, pilaster sides) belong to no facade."""
    rays_per_sample: int = 16
    """Ray directions per sample point (4 points per face) for the visibility test."""
    min_escape_fraction: float = 0.02
    """A face is seen from outside if at least this fraction of its rays escape."""
    ray_offset_m: float = 1e-3
    """Rays start this far off the surface (embree works in float32)."""
    footprint_height_m: float = 0.05
    """The footprint is the cross-section this far above the mesh's lowest point."""
    floor_height_m: float = 3.0
    """Storey height: floors = round(height / floor_height_m), at least 1."""

    def __post_init__(self) -> None:
        if self.up_axis not in ("z", "y"):
            raise ValueError(f"up_axis must be 'z' or 'y', got {self.up_axis!r}")
        for name in ("max_tilt_deg", "angle_tolerance_deg"):
            if not 0 < getattr(self, name) < 90:
                raise ValueError(f"{name} must be in (0, 90) degrees, got {getattr(self, name)}")
        for name in ("offset_tolerance_m", "gap_tolerance_m", "min_facade_width_m"):
            if getattr(self, name) < 0:
                raise ValueError(f"{name} must be >= 0 m, got {getattr(self, name)}")
        for name in ("ray_offset_m", "footprint_height_m", "floor_height_m"):
            if getattr(self, name) <= 0:
                raise ValueError(f"{name} must be > 0 m, got {getattr(self, name)}")
        if self.rays_per_sample < 1:
            raise ValueError(f"rays_per_sample must be >= 1, got {self.rays_per_sample}")
        if not 0 < self.min_escape_fraction <= 1:
            raise ValueError(
                f"min_escape_fraction must be in (0, 1], got {self.min_escape_fraction}"
            )


def import_labelled_mesh(
    path: str | Path, *, building_id: str | None = None, config: ImportConfig = ImportConfig()
) -> Building:
    """Read a user's labelled building mesh and derive its ground truth.

    Parameters
    ----------
    path
        ``.ply`` with a per-face ``label`` (class id), or ``.obj``/``.glb``/``.gltf`` whose
        objects, groups or materials are named after the classes (wall, window, roof, door,
        other; :func:`dataset.mesh_files.class_from_name`). Metres.
    building_id
        The truth's ``id``; default the file name without suffix.
    config
        Tolerances and options, :class:`ImportConfig`.

    Returns
    -------
    Building whose mesh has merged vertices, the file's face order (less faces the merge
    collapsed to a line) and facade ids 1..N, and whose truth (type ``"imported"``) counts
    only faces seen from outside.

    Raises
    ------
    ValueError
        Unreadable, empty, unlabelled, unknown class names, not closed, inconsistently
        oriented, no facade classes, or no facade seen from outside.
    """
    path = Path(path)
    mesh = _drop_collapsed_faces(read_labelled_mesh_file(path, up_axis=config.up_axis))
    _check_mesh(path, mesh)
    vertices, faces, offset = mesh.vertices_m, mesh.faces, np.zeros(3)
    if config.recentre:
        lo, hi = vertices.min(axis=0), vertices.max(axis=0)
        offset = -np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2]])
        vertices = vertices + offset
    if _signed_volume_m3(vertices, faces) < 0:  # inside-out export: every normal points in
        faces = faces[:, ::-1].copy()
    mesh = LabelledMesh(vertices, faces, mesh.face_label, mesh.face_facade)

    areas, normals = mesh.face_areas_m2(), mesh.face_normals()
    is_facade_class = np.isin(mesh.face_label, [int(c) for c in FACADE_CLASSES])
    intersector = embree_intersector(vertices, faces)
    visible = np.zeros(len(faces), dtype=bool)
    visible[is_facade_class] = escape_fractions(
        intersector, mesh.triangles_m[is_facade_class], normals[is_facade_class],
        rays_per_sample=config.rays_per_sample, offset_m=config.ray_offset_m,
    ) >= config.min_escape_fraction
    groups = group_facades(
        mesh.triangles_m, normals, areas, visible,
        max_tilt_deg=config.max_tilt_deg,
        angle_tolerance_deg=config.angle_tolerance_deg,
        offset_tolerance_m=config.offset_tolerance_m,
        gap_tolerance_m=config.gap_tolerance_m,
        min_width_m=config.min_facade_width_m,
    )
    if not groups:
        raise ValueError(
            f"{path}: no wall, window or door faces upright and seen from outside form a "
            f"facade at least {config.min_facade_width_m} m wide; check the labels and that "
            "the normals point outwards"
        )
    face_facade = facade_ids_of_faces(groups, len(faces))
    mesh = LabelledMesh(vertices, faces, mesh.face_label, face_facade)

    facades = tuple(
        _facade_truth(i + 1, g, mesh, areas, normals) for i, g in enumerate(groups)
    )
    z_min = float(vertices[:, 2].min())
    height_m = float(vertices[:, 2].max()) - z_min
    footprint = cross_section_footprint(
        vertices, faces, z_min + config.footprint_height_m, intersector
    )
    window, wall, door = (sum(getattr(f, k) for f in facades)
                          for k in ("window_area_m2", "wall_area_m2", "door_area_m2"))
    gross = gross_facade_area_m2(wall, window, door)
    truth = BuildingTruth(
        id=building_id if building_id is not None else path.stem,
        type="imported",
        floors=max(1, round(height_m / config.floor_height_m)),
        height_m=height_m,
        window_area_m2=window,
        facade_area_m2=gross,
        wall_area_m2=wall,
        door_area_m2=door,
        wwr=wwr_from_areas(window, wall, door),
        footprint=polygon_to_geojson(footprint),
        footprint_area_m2=float(footprint.area),
        facades=facades,
        name=path.name,
        extra={
            "source_file": path.name,
            "offset_m": [float(x) for x in offset],
            "hidden_area_m2": _class_areas(mesh, areas, is_facade_class & ~visible),
            "unassigned_area_m2": _class_areas(
                mesh, areas, visible & (face_facade == NO_FACADE)
            ),
            "import_config": asdict(config),
        },
    )
    return Building(mesh=mesh, truth=truth)


def _drop_collapsed_faces(mesh: LabelledMesh) -> LabelledMesh:
    """Without faces that merging made a line or a point (zero area, and their edges pair up)."""
    f = mesh.faces
    keep = (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 2] != f[:, 0])
    if keep.all():
        return mesh
    return LabelledMesh(mesh.vertices_m, f[keep], mesh.face_label[keep], mesh.face_facade[keep])


def _check_mesh(path: Path, mesh: LabelledMesh) -> None:
    if len(mesh.faces) == 0:
        raise ValueError(f"{path} holds no faces; export the building's surfaces as triangles")
    if not np.isin(mesh.face_label, [int(c) for c in FACADE_CLASSES]).any():
        raise ValueError(
            f"{path} has no wall, window or door faces (labels present: "
            f"{', '.join(SemanticClass(c).name.lower() for c in np.unique(mesh.face_label))}); "
            "label the facade surfaces wall, window or door"
        )
    edges = np.sort(mesh.faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    n_open, n_shared = int((counts == 1).sum()), int((counts > 2).sum())
    if n_open or n_shared:
        raise ValueError(
            f"{path} is not a closed mesh: {n_open} open edge(s) and {n_shared} edge(s) shared "
            "by more than two faces; close the holes (and snap T-junctions) in the authoring "
            "tool, e.g. Blender 'Merge by Distance' and 'Fill Holes', so the surface encloses "
            "the building"
        )
    directed = mesh.faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
    if len(np.unique(directed, axis=0)) != len(directed):
        raise ValueError(
            f"{path}: faces are not consistently oriented (some normals point inwards); "
            "recalculate normals outside in the authoring tool (Blender: Mesh > Normals > "
            "Recalculate Outside)"
        )


def _signed_volume_m3(vertices_m: np.ndarray, faces: np.ndarray) -> float:
    t = vertices_m[faces]
    return float(np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6.0)


def _facade_truth(
    facade_id: int, group: FacadeGroup, mesh: LabelledMesh, areas: np.ndarray, normals: np.ndarray
) -> FacadeTruth:
    f = group.face_index
    by_class = {
        c: float(areas[f][mesh.face_label[f] == c].sum()) for c in FACADE_CLASSES
    }
    window, wall, door = (by_class[SemanticClass.WINDOW], by_class[SemanticClass.WALL],
                          by_class[SemanticClass.DOOR])
    gross = gross_facade_area_m2(wall, window, door)
    z = mesh.triangles_m[f][:, :, 2]
    height = float(z.max() - z.min())
    h = normals[f, :2] / np.linalg.norm(normals[f, :2], axis=1, keepdims=True)
    spread = np.degrees(np.arccos(np.clip(h @ np.asarray(group.normal[:2]), -1.0, 1.0)).max())
    curved = bool(spread > CURVED_SPREAD_DEG)
    # A curved facade's width is its mean width (area / height), not its chord.
    width = gross / height if curved else group.along_m[1] - group.along_m[0]
    return FacadeTruth(
        id=facade_id,
        normal=group.normal,
        width_m=float(width),
        height_m=height,
        window_area_m2=window,
        wall_area_m2=wall,
        door_area_m2=door,
        facade_area_m2=gross,
        wwr=wwr_from_areas(window, wall, door),
        curved=curved,
    )


def _class_areas(mesh: LabelledMesh, areas: np.ndarray, keep: np.ndarray) -> dict[str, float]:
    return {
        c.name.lower(): float(areas[keep & (mesh.face_label == c)].sum()) for c in FACADE_CLASSES
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m dataset.importer",
        description="Import your own labelled building mesh: derive its ground truth (facades, "
        "window/wall/door areas seen from outside, WWR, footprint) and write building.json and "
        "mesh.ply (with facade ids) into a scene folder. The mesh must be closed; label faces "
        "with a PLY 'label' property (0 background, 1 wall, 2 window, 3 roof, 4 door, 5 other) "
        "or name OBJ/GLB objects, groups or materials after the classes.",
    )
    parser.add_argument("mesh", type=Path, help="labelled mesh: .ply, .obj, .glb or .gltf")
    parser.add_argument("scene_dir", type=Path, help="folder to write building.json and mesh.ply")
    parser.add_argument("--id", dest="building_id", help="building id (default: file name)")
    defaults = ImportConfig()
    parser.add_argument("--up-axis", choices=("z", "y"), default=defaults.up_axis,
                        help="the file's up axis; glTF from Blender is y (default: %(default)s)")
    parser.add_argument("--footprint-height-m", type=float, default=defaults.footprint_height_m,
                        help="footprint section height above the lowest point "
                        "(default: %(default)s)")
    parser.add_argument("--floor-height-m", type=float, default=defaults.floor_height_m,
                        help="storey height for the floor count (default: %(default)s)")
    parser.add_argument("--keep-position", action="store_true",
                        help="keep the file's coordinates instead of centring the building "
                        "on the origin with its lowest point at z = 0")
    add_debug_flag(parser)
    args = parser.parse_args(argv)

    def body() -> int:
        config = ImportConfig(
            up_axis=args.up_axis, recentre=not args.keep_position,
            footprint_height_m=args.footprint_height_m, floor_height_m=args.floor_height_m,
        )
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
