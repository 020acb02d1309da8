"""Measures of an imported IFC building that the importer does not use, to check it by.

- :func:`elevation_areas`: orthographic views of the wall, window and door surfaces above
  the ground from :data:`ELEVATION_DIRECTIONS` horizontal directions; only those surfaces
  occlude (a wall behind a balcony or under the eaves counts), each surface is counted in
  the direction nearest its normal (one ray at a random point of each grid cell: no
  aliasing with mullions), and points lying inside another solid are left out (a ray from
  5 mm in front of the point towards the viewer meets a face from behind: a gable running
  into its roof slab). The facade, window and WWR an architect would measure on
  elevation drawings -- against the importer's rays from every face over its hemisphere,
  cuts and facade grouping.
- :func:`plan_footprint`: the union of the plan projections of the elements that stand at
  the footprint height, gaps under 2 mm closed, holes filled -- against the importer's
  cross-section and inside rule.
- the declared ``OverallWidth x OverallHeight`` of each IfcWindow is in the import's own
  record (``truth.extra["ifc"]["windows"]``).

Used by ``bench/ifc_corpus.py`` and ``tests/dataset/importers/test_ifc_real.py``.
"""

from __future__ import annotations

import numpy as np
import shapely
from shapely import affinity
from shapely.ops import unary_union

from dataset.importers.ifc.convert import IfcModel
from dataset.importers.import_config import ImportConfig
from envelope.classes import FACADE_CLASSES, SemanticClass
from envelope.footprint import geojson_to_polygon
from envelope.geometry.raycast import Raycaster
from envelope.mesh import LabelledMesh
from envelope.truth import BuildingTruth
from envelope.wwr import ClassAreas

ELEVATION_DIRECTIONS = 72
"""Elevations 5 degrees apart."""
PLAN_CLOSING_M = 1e-3
"""Gaps narrower than twice this between the plan projections of elements are closed."""
INSIDE_PROBE_M = 0.005
"""A counted point is probed this far in front of its surface for lying inside a solid."""
JITTER_SEED = 0
"""Seed of the elevation rays' positions within their grid cells (stratified sampling)."""
"""A counted point is probed this far in front of its surface for lying inside a solid."""


def elevation_areas(mesh: LabelledMesh, spacing_m: float = 0.1) -> dict:
    """Facade, window, wall and door areas (m²) and WWR seen on orthographic elevations of
    the facade-class surfaces above the ground (module docstring).

    Parameters
    ----------
    mesh
        An imported building's mesh (ground at z = 0).
    spacing_m
        Distance between the elevation rays; the areas are counts of rays times its square.
    """
    tri = mesh.triangles_m
    keep = np.isin(mesh.face_label, [int(c) for c in FACADE_CLASSES]) & (
        tri[:, :, 2].mean(axis=1) > 0)
    sub = LabelledMesh(mesh.vertices_m, mesh.faces[keep], mesh.face_label[keep],
                       mesh.face_facade[keep])
    caster, everything = Raycaster(sub), Raycaster(mesh)
    normals = caster.face_normals
    upright = np.abs(normals[:, 2]) <= np.sin(np.deg2rad(ImportConfig().max_tilt_deg))
    step = 2 * np.pi / ELEVATION_DIRECTIONS
    face_bin = np.round(np.arctan2(normals[:, 1], normals[:, 0]) / step).astype(int)
    face_bin %= ELEVATION_DIRECTIONS
    lo, hi = caster.bounds_m
    centre = (lo + hi) / 2
    radius = float(np.linalg.norm(hi[:2] - lo[:2])) / 2 + 1.0
    zs = np.arange(max(lo[2], 0.0) + spacing_m / 2, hi[2], spacing_m)
    ts = np.arange(-radius, radius, spacing_m) + spacing_m / 2
    grid_t, grid_z = (g.reshape(-1) for g in np.meshgrid(ts, zs, indexing="ij"))
    rng = np.random.default_rng(JITTER_SEED)
    area = {c: 0.0 for c in FACADE_CLASSES}
    for k in range(ELEVATION_DIRECTIONS):
        d = np.array([np.cos(k * step), np.sin(k * step), 0.0])  # towards the viewer
        tangent = np.array([-d[1], d[0], 0.0])
        # One ray at a random point of each grid cell: no aliasing with mullions or bricks.
        jitter = (rng.random((len(grid_t), 2)) - 0.5) * spacing_m
        origins = (centre + radius * d)[None, :] + (grid_t + jitter[:, 0])[:, None] * tangent
        origins[:, 2] = grid_z + jitter[:, 1]
        face, t = caster.first_hit(origins, np.broadcast_to(-d, origins.shape).copy())
        counted = face >= 0
        counted[counted] = upright[face[counted]] & (face_bin[face[counted]] == k)
        counted[counted] = normals[face[counted]] @ d > 0
        points = origins[counted] - (t[counted] - INSIDE_PROBE_M)[:, None] * d
        back, _ = everything.first_hit(points, np.broadcast_to(d, points.shape).copy())
        inside = (back >= 0) & (everything.face_normals[np.maximum(back, 0)] @ d > 0)
        f = face[counted][~inside]
        weights = spacing_m ** 2 / (normals[f] @ d)
        labels = sub.face_label[f]
        for c in FACADE_CLASSES:
            area[c] += float(weights[labels == c].sum())
    window, wall, door = (area[SemanticClass.WINDOW], area[SemanticClass.WALL],
                          area[SemanticClass.DOOR])
    totals = ClassAreas(window, wall, door)
    return {"facade_m2": totals.gross_m2, "window_m2": window, "wall_m2": wall,
            "door_m2": door, "wwr": totals.wwr or 0.0}


def plan_footprint(model: IfcModel, z_m: float):
    """Union of the plan projections of the elements that reach height ``z_m`` (world frame
    of the file), holes filled."""
    tri = model.mesh.triangles_m
    zlo = np.full(len(model.elements), np.inf)
    zhi = np.full(len(model.elements), -np.inf)
    np.minimum.at(zlo, model.face_element, tri[:, :, 2].min(axis=1))
    np.maximum.at(zhi, model.face_element, tri[:, :, 2].max(axis=1))
    standing = (zlo <= z_m) & (zhi >= z_m)  # touching counts: a transom ending there
    faces = tri[standing[model.face_element]][:, :, :2]
    polygons = shapely.polygons(faces)
    polygons = polygons[shapely.area(polygons) > 1e-12]
    # Closing by 1 mm joins elements that exporters leave a hair apart at their corners.
    union = unary_union(shapely.make_valid(polygons)).buffer(
        PLAN_CLOSING_M, join_style="mitre").buffer(-PLAN_CLOSING_M, join_style="mitre")
    parts = getattr(union, "geoms", [union])
    return unary_union([shapely.Polygon(p.exterior) for p in parts
                        if isinstance(p, shapely.Polygon) and p.area > 0.01])


def footprint_iou(plan, truth: BuildingTruth) -> float:
    """IoU of a footprint in the file's frame with the imported truth's (recentred) one."""
    footprint = affinity.translate(geojson_to_polygon(truth.footprint),
                                   *(-np.asarray(truth.extra["offset_m"][:2])))
    return float(plan.intersection(footprint).area / plan.union(footprint).area)
