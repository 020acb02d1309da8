"""A closed mesh's footprint: its horizontal cross-section at one height, as a shapely polygon.

The section's segments are snapped to :data:`SNAP_GRID_M` and polygonised; each face of
that planar arrangement is solid if a point inside it is inside the building (the one
inside rule, :meth:`envelope.geometry.raycast.Raycaster.contains`: the union of the mesh's bodies).
The footprint is the solid's outline: every hole in the solid is filled (rooms between
exterior and interior walls of a BIM model, the insides of partitions) unless it is open
to the sky -- a vertical ray from it leaves the mesh -- which makes it a courtyard, kept
as a hole. Disjoint solids give a MultiPolygon.
"""

from __future__ import annotations

import numpy as np
import shapely
from shapely.geometry import MultiLineString, MultiPolygon, Polygon
from shapely.ops import polygonize, unary_union

from envelope.geometry.raycast import Raycaster

SNAP_GRID_M = 1e-6  # joins segment ends that float round-off left a few nm apart


def cross_section_footprint(raycaster: Raycaster, z_m: float) -> Polygon | MultiPolygon:
    """Footprint of a building mesh from its cross-section at height ``z_m``.

    Parameters
    ----------
    raycaster
        Over the building's mesh: closed bodies (touching or overlapping), world frame, z up.
    z_m
        Section height in metres; choose one that no horizontal face lies in.

    Returns
    -------
    Polygon (or MultiPolygon for disjoint parts), world x/y metres.

    Raises
    ------
    ValueError
        If the plane misses the mesh.
    """
    import trimesh

    mesh = trimesh.Trimesh(raycaster.mesh.vertices_m, raycaster.mesh.faces, process=False)
    segments = trimesh.intersections.mesh_plane(mesh, [0.0, 0.0, 1.0], [0.0, 0.0, z_m])
    if len(segments) == 0:
        raise ValueError(
            f"the section at z = {z_m:.3f} m misses the mesh (z from "
            f"{mesh.bounds[0, 2]:.3f} to {mesh.bounds[1, 2]:.3f} m); choose another height"
        )
    lines = shapely.set_precision(MultiLineString([s[:, :2] for s in segments]), SNAP_GRID_M)
    regions = [p for p in polygonize(unary_union(lines)) if p.area > 0]
    if not regions:
        raise ValueError(
            f"the section at z = {z_m:.3f} m has no closed outline; is the mesh closed?"
        )
    inside_pts = np.array([[*p.representative_point().coords[0], z_m] for p in regions])
    solid = unary_union([p for p, inside in zip(regions, raycaster.contains(inside_pts))
                         if inside])
    if solid.is_empty:
        raise ValueError(f"the section at z = {z_m:.3f} m holds no solid; is the mesh inside out?")
    return _fill_roofed_holes(solid, z_m, raycaster)


def _fill_roofed_holes(solid, z_m: float, raycaster: Raycaster) -> Polygon | MultiPolygon:
    parts = list(solid.geoms) if isinstance(solid, MultiPolygon) else [solid]
    filled = []
    for part in parts:
        holes = []
        for ring in part.interiors:
            free = Polygon(ring).difference(solid)
            if free.is_empty:
                continue
            point = free.representative_point()
            if raycaster.open_to_sky(np.array([[point.x, point.y, z_m]]))[0]:
                holes.append(ring)
        filled.append(Polygon(part.exterior, holes))
    # Drop the collinear vertices that every triangle edge crossing the plane leaves behind.
    footprint = unary_union(filled).simplify(SNAP_GRID_M, preserve_topology=True)
    if isinstance(footprint, MultiPolygon) and len(footprint.geoms) == 1:
        return footprint.geoms[0]
    return footprint

