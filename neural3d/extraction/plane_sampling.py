"""Window and wall areas read from the fields on each facade plane's grid (not mesh labels).

Each facade plane (azimuth, offset) found on the mesh by
:mod:`neural3d.extraction.facade_planes` is covered by a grid of ``cell_m`` squares over
the extent of its triangles. From every cell centre the SDF is probed along the
plane's inward normal, from ``depth_m`` in front of the plane to ``depth_m``
behind it; the first outside-to-inside crossing is the facade there (the wall,
or the pane at the back of a window recess), and the semantic field's class at
that point labels the cell. A cell whose probe finds no crossing (beyond the
wall's end, or in front of another wing), or whose crossing faces more than
45 degrees away from the plane (the chamfered corner of the next wall), is no
facade. So an opening counts
with its projected area, as the truth does, and reveals, sills and labels
bleeding around an opening's edge in the mesh do not add area.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from dataset.core.classes import SemanticClass
from dataset.core.mesh import triangle_normals
from neural3d.extraction.facade_planes import plane_frame

SdfFn = Callable[[np.ndarray], np.ndarray]  # (N, 3) world m -> (N,) m, positive outside
LabelFn = Callable[[np.ndarray], np.ndarray]  # (N, 3) world m -> (N,) dataset class ids


@dataclass(frozen=True)
class PlaneExtent:
    """A facade plane {x : x.N = offset_m}, N horizontal at ``azimuth_deg``, and its extent.

    ``u`` runs along the plane (tangent (-N_y, N_x, 0)), ``z`` up; metres.
    """

    azimuth_deg: float
    offset_m: float
    u_min_m: float
    u_max_m: float
    z_min_m: float
    z_max_m: float

    def frame(self) -> tuple[np.ndarray, np.ndarray]:
        """(normal (3,), tangent (3,)) unit vectors, world frame."""
        return plane_frame(self.azimuth_deg)


@dataclass(frozen=True)
class PlaneAreas:
    """Areas in m² counted on one plane: window, wall, door (cells by class) and cells probed."""

    window_m2: float
    wall_m2: float
    door_m2: float
    cells: int


def plane_extents(vertices_m: np.ndarray, faces: np.ndarray,
                  planes: tuple[tuple[float, float], ...], *, slab_m: float,
                  max_angle_deg: float) -> tuple[PlaneExtent, ...]:
    """Extent of each plane (azimuth deg, offset m): the triangles within ``slab_m`` facing it.

    ``vertices_m`` (V, 3), ``faces`` (F, 3) outward; a triangle faces a plane when its
    normal is within ``max_angle_deg`` of the plane's. Planes with no such triangle
    are left out.
    """
    tri = vertices_m[faces]
    normal = triangle_normals(tri)
    centroid = tri.mean(axis=1)
    out = []
    for az, off in planes:
        probe = PlaneExtent(az, off, 0.0, 0.0, 0.0, 0.0)
        n, t = probe.frame()
        on = ((np.abs(centroid @ n - off) <= slab_m)
              & (normal @ n >= np.cos(np.radians(max_angle_deg))))
        if not on.any():
            continue
        pts = tri[on].reshape(-1, 3)
        u = pts @ t
        out.append(PlaneExtent(az, off, float(u.min()), float(u.max()), float(pts[:, 2].min()),
                               float(pts[:, 2].max())))
    return tuple(out)


def plane_sampled_areas(sdf_fn: SdfFn, label_fn: LabelFn, extent: PlaneExtent, *,
                        cell_m: float, depth_m: float, probes: int = 25) -> PlaneAreas:
    """Window, wall and door area (m²) of one plane, from the fields (see the module docstring).

    ``probes`` SDF samples per cell along the normal over ``[-depth_m, depth_m]``
    (the crossing is placed by linear interpolation between two of them).
    """
    if cell_m <= 0 or depth_m <= 0 or probes < 2:
        raise ValueError(f"need cell_m > 0, depth_m > 0 and probes >= 2, got {cell_m}, "
                         f"{depth_m}, {probes}")
    n, t = extent.frame()
    nu = max(1, int(np.ceil((extent.u_max_m - extent.u_min_m) / cell_m)))
    nz = max(1, int(np.ceil((extent.z_max_m - extent.z_min_m) / cell_m)))
    u = extent.u_min_m + (np.arange(nu) + 0.5) * cell_m
    z = extent.z_min_m + (np.arange(nz) + 0.5) * cell_m
    uu, zz = (a.ravel() for a in np.meshgrid(u, z, indexing="ij"))
    on_plane = extent.offset_m * n + uu[:, None] * t + zz[:, None] * np.array([0.0, 0.0, 1.0])
    s = np.linspace(depth_m, -depth_m, probes)  # outside to inside along the normal
    pts = on_plane[:, None, :] + s[None, :, None] * n  # (C, P, 3)
    sdf = sdf_fn(pts.reshape(-1, 3)).reshape(len(on_plane), probes)
    enters = (sdf[:, :-1] > 0) & (sdf[:, 1:] <= 0)  # (C, P - 1)
    found = enters.any(axis=1) & (sdf[:, 0] > 0)  # from outside, not behind another wing
    i = np.argmax(enters, axis=1)
    rows = np.flatnonzero(found)
    a, b = sdf[rows, i[rows]], sdf[rows, i[rows] + 1]
    frac = a / np.where(a - b > 0, a - b, 1.0)
    depth = s[i[rows]] + frac * (s[i[rows] + 1] - s[i[rows]])
    hit = on_plane[rows] + depth[:, None] * n
    # A cell counts only where the surface faces the plane (within 45 degrees): the
    # chamfered corner between two walls is then split between them, not counted twice.
    step = 0.25 * cell_m
    offsets = np.concatenate([np.zeros((1, 3)), step * np.eye(3)])
    d = sdf_fn((hit[:, None, :] + offsets).reshape(-1, 3)).reshape(len(hit), 4)
    grad = d[:, 1:] - d[:, :1]
    facing = grad @ n > np.cos(np.radians(45.0)) * np.linalg.norm(grad, axis=1)
    labels = np.where(facing, label_fn(hit), -1)
    cell_area = cell_m * cell_m
    return PlaneAreas(
        window_m2=float((labels == SemanticClass.WINDOW).sum() * cell_area),
        wall_m2=float((labels == SemanticClass.WALL).sum() * cell_area),
        door_m2=float((labels == SemanticClass.DOOR).sum() * cell_area),
        cells=len(on_plane),
    )
