"""Make the example user meshes: a small BIM-like building as labelled PLY and OBJ.

Run ``python -m dataset.examples.make_example_bim`` to rewrite ``example_bim.ply`` and
``example_bim.obj`` next to this file. The building is built from axis-aligned boxes on a
grid, so it is closed and conforming by construction and every area is known by hand
(docs/importing.md): a 12 x 8 x 6.3 m box with 0.3 m walls, floor and roof slabs, an
interior partition wall, six windows on the south facade, two on the east and a door on
the north. The interior faces are labelled like the elements they bound and must not count.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Literal

import numpy as np

from envelope.atomic import write_text_atomic
from envelope.classes import CLASS_NAMES, NO_FACADE, SemanticClass
from envelope.mesh import LabelledMesh, write_labelled_ply

Box = tuple[tuple[float, float, float], tuple[float, float, float], SemanticClass]
"""(min corner, max corner, class) of a solid box, metres."""
ObjNaming = Literal["objects", "groups", "materials"]

WALL, WINDOW, DOOR = SemanticClass.WALL, SemanticClass.WINDOW, SemanticClass.DOOR


def boxes_mesh(boxes: list[Box]) -> LabelledMesh:
    """Closed labelled surface of the union of boxes (later boxes paint over earlier ones).

    The boxes are voxelised on the grid of all their bounds; the surface is every grid cell
    face between a filled and an empty cell, so it is watertight without T-junctions.
    Upright faces take the class of the box they bound; upward faces are roof when nothing
    is above them, else other (floor tops); downward faces are other.
    """
    breaks = [np.unique([b[k][axis] for b in boxes for k in (0, 1)]) for axis in range(3)]
    centres = [(b[1:] + b[:-1]) / 2 for b in breaks]
    material = np.zeros([len(c) for c in centres], dtype=np.uint8)
    grid = np.stack(np.meshgrid(*centres, indexing="ij"), axis=-1)
    for lo, hi, cls in boxes:
        inside = np.all((grid > np.asarray(lo)) & (grid < np.asarray(hi)), axis=-1)
        material[inside] = cls
    filled = material > 0
    shape = np.array(filled.shape) + 1
    node = np.arange(np.prod(shape)).reshape(shape)
    # covered[i, j, k]: some cell at height k or above in column (i, j) is filled.
    covered = np.flip(np.cumsum(np.flip(filled, axis=2), axis=2), axis=2) > 0
    faces, labels = [], []
    for axis in range(3):
        b, c = (axis + 1) % 3, (axis + 2) % 3
        pad = [(0, 0)] * 3
        pad[axis] = (1, 1)
        f = np.pad(filled, pad)
        m = np.pad(material, pad)
        lo_cell = np.take(f, range(0, f.shape[axis] - 1), axis=axis)
        hi_cell = np.take(f, range(1, f.shape[axis]), axis=axis)
        for sign, (solid, empty) in ((+1, (lo_cell, hi_cell)), (-1, (hi_cell, lo_cell))):
            for idx in np.argwhere(solid & ~empty):
                plane = idx[axis]  # node index of the face plane along `axis`
                cell = idx.copy()
                cell[axis] = plane - 1 if sign > 0 else plane  # the filled cell, unpadded
                corners = []
                for db, dc in ((0, 0), (1, 0), (1, 1), (0, 1)):
                    n = idx.copy()
                    n[b] += db
                    n[c] += dc
                    corners.append(node[tuple(n)])
                if sign < 0:
                    corners = corners[::-1]
                faces += [corners[:3], [corners[0], corners[2], corners[3]]]
                labels += [_face_class(axis, sign, cell, m, covered, pad)] * 2
    vertices = np.stack(np.meshgrid(*breaks, indexing="ij"), axis=-1).reshape(-1, 3)
    faces = np.asarray(faces, dtype=np.int64)
    used, compact = np.unique(faces, return_inverse=True)
    return LabelledMesh(
        vertices[used], compact.reshape(-1, 3), np.asarray(labels), np.full(len(faces), NO_FACADE)
    )


def _face_class(axis, sign, cell, padded_material, covered, pad) -> int:
    if axis == 2 and sign > 0:
        above = cell[2] + 1 < covered.shape[2] and covered[cell[0], cell[1], cell[2] + 1]
        return int(SemanticClass.OTHER if above else SemanticClass.ROOF)
    if axis == 2:
        return int(SemanticClass.OTHER)
    p = cell.copy()
    p[axis] += pad[axis][0]
    return int(padded_material[tuple(p)])


def example_bim_boxes() -> list[Box]:
    """The shipped example: hollow 12 x 8 x 6.3 m box, partition, 8 windows, 1 door."""
    t, top = 0.3, 6.3
    boxes: list[Box] = [
        ((0, 0, 0), (12, 8, t), WALL),  # floor slab
        ((0, 0, top - t), (12, 8, top), WALL),  # roof slab
        ((0, 0, 0), (12, t, top), WALL),  # south wall
        ((0, 8 - t, 0), (12, 8, top), WALL),  # north wall
        ((0, 0, 0), (t, 8, top), WALL),  # west wall
        ((12 - t, 0, 0), (12, 8, top), WALL),  # east wall
        ((5.85, t, t), (6.15, 8 - t, top - t), WALL),  # interior partition
    ]
    for x0 in (1.5, 5.25, 9.0):  # south: two rows of three 1.5 x 1.2 m windows
        for z0 in (1.2, 4.0):
            boxes.append(((x0, 0, z0), (x0 + 1.5, t, z0 + 1.2), WINDOW))
    for y0 in (2.0, 4.5):  # east: two 1.5 x 1.2 m windows
        boxes.append(((12 - t, y0, 1.2), (12, y0 + 1.5, 2.4), WINDOW))
    boxes.append(((8.0, 8 - t, t), (9.0, 8, 2.4), DOOR))  # north: 1.0 x 2.1 m door
    return boxes


def write_labelled_obj(path: str | Path, mesh: LabelledMesh, *, naming: ObjNaming) -> None:
    """Write ``mesh`` as OBJ with one part per class, named by object, group or material."""
    lines = ["# envelope-bench example: parts named after semantic classes"]
    lines += [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in mesh.vertices_m]
    keyword = {"objects": "o", "groups": "g", "materials": "usemtl"}[naming]
    for cls in np.unique(mesh.face_label):
        lines.append(f"{keyword} {CLASS_NAMES[cls].capitalize()}")
        lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in mesh.faces[mesh.face_label == cls]]
    write_text_atomic(path, "\n".join(lines) + "\n")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        description="Write the example BIM-like building (example_bim.ply with face labels, "
        "example_bim.obj with objects named after classes) for tests and docs."
    )
    parser.add_argument("--out-dir", type=Path, default=Path(__file__).parent,
                        help="folder to write into (default: next to this script)")
    args = parser.parse_args(argv)
    try:
        mesh = boxes_mesh(example_bim_boxes())
        write_labelled_ply(args.out_dir / "example_bim.ply", mesh)
        write_labelled_obj(args.out_dir / "example_bim.obj", mesh, naming="objects")
    except (ValueError, OSError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print(f"wrote {len(mesh.faces)} faces to {args.out_dir}/example_bim.{{ply,obj}}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
