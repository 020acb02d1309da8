"""Checks that a generated building's mesh agrees with its analytic truth (shared by tests).

Each check is independent of the generator's code: it looks only at the labelled
mesh and the BuildingTruth.
"""

from __future__ import annotations

from collections import defaultdict

import numpy as np
import shapely
import trimesh
from shapely.geometry import MultiLineString, Polygon
from shapely.ops import polygonize, unary_union

from envelope.classes import NO_FACADE, SemanticClass
from envelope.footprint import geojson_to_polygon
from envelope.mesh import area_by_class_m2
from envelope.truth import Building

AREA_RTOL = 1e-6  # the task's bound; vertex merging rounds to 1 nm, so errors are ~1e-9
FOOTPRINT_MIN_IOU = 0.999
SECTION_Z_M = 0.01  # just above ground, below every door threshold


def _close(a: float, b: float) -> bool:
    return abs(a - b) <= AREA_RTOL * max(abs(b), 1.0)


def check_areas(building: Building) -> None:
    """Window, door, wall and gross area per facade and in total equal the labelled faces."""
    mesh, truth = building.mesh, building.truth
    wall, window, door = SemanticClass.WALL, SemanticClass.WINDOW, SemanticClass.DOOR
    total = area_by_class_m2(mesh)
    assert _close(total[wall], truth.wall_area_m2), (total, truth.wall_area_m2)
    assert _close(total[window], truth.window_area_m2), (total, truth.window_area_m2)
    assert _close(total[door], truth.door_area_m2), (total, truth.door_area_m2)
    assert _close(sum(total.values()), truth.facade_area_m2)
    ids = set(np.unique(mesh.face_facade[mesh.face_facade != NO_FACADE]).tolist())
    assert ids == {f.id for f in truth.facades}
    normals, areas = mesh.face_normals(), mesh.face_areas_m2()
    for f in truth.facades:
        got = area_by_class_m2(mesh, facade_id=f.id)
        assert _close(got[wall], f.wall_area_m2), (f.id, got, f)
        assert _close(got[window], f.window_area_m2), (f.id, got, f)
        assert _close(got[door], f.door_area_m2), (f.id, got, f)
        assert _close(sum(got.values()), f.facade_area_m2)
        assert abs(f.wwr - f.window_area_m2 / f.facade_area_m2) < 1e-12
        # Every face of a facade faces the truth's normal (exactly, unless curved).
        mine = mesh.face_facade == f.id
        cos = normals[mine] @ np.asarray(f.normal)
        if f.curved:
            assert cos.min() > 0.0
            mean = (normals[mine] * areas[mine, None]).sum(axis=0)
            assert np.allclose(mean / np.linalg.norm(mean), f.normal, atol=1e-6)
        else:
            assert cos.min() > 1 - 1e-9, (f.id, cos.min())
    # Reveals, roofs and attached parts belong to no facade; facade faces are facade classes.
    facade_classes = np.isin(mesh.face_label, [wall, window, door])
    assert np.all(mesh.face_facade[~facade_classes] == NO_FACADE)


def check_footprint(building: Building) -> None:
    """The truth footprint equals the mesh's cross-section just above ground (IoU)."""
    tm = trimesh.Trimesh(building.mesh.vertices_m, building.mesh.faces, process=False)
    segments = trimesh.intersections.mesh_plane(tm, [0, 0, 1.0], [0, 0, SECTION_Z_M])
    lines = MultiLineString([s[:, :2] for s in segments])
    section = unary_union(list(polygonize(unary_union(shapely.set_precision(lines, 1e-7)))))
    truth = geojson_to_polygon(building.truth.footprint)
    iou = section.intersection(truth).area / section.union(truth).area
    assert iou >= FOOTPRINT_MIN_IOU, iou
    assert _close(truth.area, building.truth.footprint_area_m2)


def check_closed_bodies(building: Building) -> int:
    """Every edge joins exactly two faces with opposite directions; each body encloses volume.

    Returns the number of connected bodies.
    """
    faces = building.mesh.faces
    directed = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    keys, counts = np.unique(directed, axis=0, return_counts=True)
    assert counts.max() == 1, "an edge is used twice in one direction (inconsistent winding)"
    reverse = {tuple(k) for k in keys[:, ::-1].tolist()}
    assert all(tuple(k) in reverse for k in keys.tolist()), "open edge (hole or T-junction)"
    tm = trimesh.Trimesh(building.mesh.vertices_m, faces, process=False)
    bodies = tm.split(only_watertight=False)
    for body in bodies:
        assert body.is_watertight and body.is_winding_consistent
        assert body.volume > 0, "faces point inward"
    return len(bodies)


def check_no_coplanar_overlap(building: Building) -> None:
    """Faces that lie in one plane (either side) never overlap: summed area equals union area."""
    mesh = building.mesh
    normals, tris = mesh.face_normals(), mesh.triangles_m
    # One key per unoriented plane, so that back-to-back faces are compared too.
    first = np.argmax(np.abs(normals) > 1e-9, axis=1)
    normals = normals * np.sign(normals[np.arange(len(normals)), first])[:, None]
    offsets = np.einsum("ij,ij->i", normals, tris[:, 0])
    groups: dict[tuple, list[int]] = defaultdict(list)
    keys = np.round(np.column_stack([normals, offsets]), 6) + 0.0
    for i, key in enumerate(map(tuple, keys)):
        groups[key].append(i)
    for key, idx in groups.items():
        if len(idx) < 2:
            continue
        n = np.asarray(key[:3])
        u = np.cross([0, 0, 1.0] if abs(n[2]) < 0.9 else [1.0, 0, 0], n)
        u /= np.linalg.norm(u)
        basis = np.stack([u, np.cross(n, u)])
        flat = tris[idx] @ basis.T
        polys = [Polygon(t) for t in flat]
        summed = sum(p.area for p in polys)
        union = shapely.union_all(polys).area
        assert abs(summed - union) <= 1e-6 * max(union, 1.0), (key, summed, union)


def check_building(building: Building) -> None:
    """All the checks above."""
    check_areas(building)
    check_footprint(building)
    check_closed_bodies(building)
    check_no_coplanar_overlap(building)
