"""Cross-check an imported building's truth against what the renderer draws.

Each facade is rendered with the project's renderer
(:func:`dataset.rendering.render.render_ground_truth`) from far in front, looking along its
inward normal: a pinhole camera :data:`CAMERA_DISTANCE_M` away whose focal length makes a
pixel :data:`PIXEL_M` wide on the facade's plane, so the view is orthographic to
``depth spread / distance`` (< 0.02 % for a facade 0.3 m deep). Pixels whose facade id is
the facade's are counted per class and back-projected: each is ``(distance / focal)^2`` m²
of the facade plane. What a pixel shows comes from the mesh alone, the truth from the
polygons' regions (:mod:`dataset.importers.citygml.facades`), so the two agree only if the
triangulation, the holes, the opening fillers and the facade ids are right.

Each facade is rendered twice: ``bare`` with only the facade's own faces (the check of the
truth: nothing but the facade's surfaces and fillers decides a pixel), and
``rendered`` with the whole mesh, as the benchmark's cameras see it: balconies, canopies,
roofs and other walls in front hide part of the facade, and the difference is that
occlusion. Large views are cut into tiles of at most :data:`TILE_PX` pixels a side.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dataset.rendering.render import render_ground_truth
from envelope.camera import Intrinsics
from envelope.classes import SemanticClass
from envelope.geometry.raycast import Raycaster
from envelope.mesh import LabelledMesh
from envelope.truth import Building

PIXEL_M = 0.01
"""Pixel size on the facade plane (1 cm). The models' corners sit on a centimetre grid, so
coarser pixels alias with it: 2 cm pixels put 4018259's and 4018206's windows 0.6-0.8 %
low, 1 cm pixels within 0.02 %."""
CAMERA_DISTANCE_M = 2000.0
TILE_PX = 1024
_UP = np.array([0.0, 0.0, 1.0])


@dataclass(frozen=True)
class FacadeCheck:
    """One facade's areas (m²) as the truth gives them and as rendered labels give them.

    ``truth_m2``, ``bare_m2`` (facade surfaces alone), ``rendered_m2`` (whole mesh): class
    name (``window``, ``wall``, ``door``) -> area. ``hidden_by_m2``: what the whole mesh
    shows where the bare render shows the facade, by class (``other``: installations,
    balconies, ground and outer floors/ceilings; ``wall``: another facade's or an
    uncovered wall in front).
    """

    facade_id: int
    truth_m2: dict[str, float]
    bare_m2: dict[str, float]
    rendered_m2: dict[str, float]
    hidden_by_m2: dict[str, float]

    def relative_error(self, name: str, *, bare: bool = True) -> float:
        """(rendered - truth) / truth of ``window``, ``door``, ``wall`` or ``gross`` (their
        sum), from the bare render or the whole mesh's; 0 when both are 0."""
        drawn = self.bare_m2 if bare else self.rendered_m2
        truth = sum(self.truth_m2.values()) if name == "gross" else self.truth_m2[name]
        rendered = sum(drawn.values()) if name == "gross" else drawn[name]
        return 0.0 if truth == rendered == 0 else (rendered - truth) / max(truth, 1e-12)


def check_facades(building: Building, *, pixel_m: float = PIXEL_M) -> list[FacadeCheck]:
    """Render every facade of ``building`` head-on and compare label areas with the truth.

    Parameters
    ----------
    building
        With ``truth.facade_outlines_m`` (as the CityGML importer writes them).
    pixel_m
        Pixel size on the facade plane, metres.
    """
    if pixel_m <= 0:
        raise ValueError(f"pixel_m must be > 0, got {pixel_m}")
    mesh = building.mesh
    whole = Raycaster(mesh)
    out = []
    for facade in building.truth.facades:
        keep = mesh.face_facade == facade.id
        bare = Raycaster(LabelledMesh(mesh.vertices_m, mesh.faces[keep], mesh.face_label[keep],
                                      mesh.face_facade[keep]))
        outline = np.asarray(building.truth.facade_outlines_m[facade.id][0])
        truth = {"window": facade.window_area_m2, "wall": facade.wall_area_m2,
                 "door": facade.door_area_m2}
        bare_m2, seen_m2, hidden_m2 = _facade_areas_m2(
            bare, whole, outline, np.asarray(facade.normal), facade.id, pixel_m)
        out.append(FacadeCheck(facade.id, truth, bare_m2, seen_m2, hidden_m2))
    return out


_CLASSES = {"window": SemanticClass.WINDOW, "wall": SemanticClass.WALL,
            "door": SemanticClass.DOOR}
_HIDERS = {"other": SemanticClass.OTHER, "roof": SemanticClass.ROOF,
           "wall": SemanticClass.WALL, "window": SemanticClass.WINDOW,
           "door": SemanticClass.DOOR}


def _facade_areas_m2(bare: Raycaster, whole: Raycaster, outline_m: np.ndarray,
                     normal: np.ndarray, facade_id: int, pixel_m: float
                     ) -> tuple[dict[str, float], dict[str, float], dict[str, float]]:
    """Back-projected areas over the facade's outline rectangle (+ 1 pixel): per class of the
    facade's pixels in the bare and the whole render, and per class of what the whole mesh
    shows where the bare render shows the facade (what hides it)."""
    tangent = np.cross(_UP, normal)
    u = outline_m @ tangent
    v = outline_m[:, 2]
    u0, u1, v0, v1 = u.min() - pixel_m, u.max() + pixel_m, v.min() - pixel_m, v.max() + pixel_m
    width, height = int(np.ceil((u1 - u0) / pixel_m)), int(np.ceil((v1 - v0) / pixel_m))
    focal = CAMERA_DISTANCE_M / pixel_m
    plane = float(outline_m[0] @ normal)
    centre = np.array([(u0 + u1) / 2, (v0 + v1) / 2])
    eye = centre[0] * tangent + centre[1] * _UP + (plane + CAMERA_DISTANCE_M) * normal
    pose = np.eye(4)
    pose[:3, 0], pose[:3, 1], pose[:3, 2], pose[:3, 3] = tangent, _UP, normal, eye
    bare_n, seen_n, hidden_n = (dict.fromkeys(_CLASSES, 0), dict.fromkeys(_CLASSES, 0),
                                dict.fromkeys(_HIDERS, 0))
    for x0 in range(0, width, TILE_PX):
        for y0 in range(0, height, TILE_PX):
            w, h = min(TILE_PX, width - x0), min(TILE_PX, height - y0)
            # Tile's left edge is u0 + x0 * pixel; the principal point is the camera centre.
            k = Intrinsics(focal, focal, (centre[0] - (u0 + x0 * pixel_m)) / pixel_m,
                           ((v1 - y0 * pixel_m) - centre[1]) / pixel_m, w, h)
            mine_bare = render_ground_truth(bare, k, pose)
            seen = render_ground_truth(whole, k, pose)
            on_bare = mine_bare.facade_ids == facade_id
            on_seen = seen.facade_ids == facade_id
            for name, c in _CLASSES.items():
                bare_n[name] += int(np.count_nonzero(on_bare & (mine_bare.labels == c)))
                seen_n[name] += int(np.count_nonzero(on_seen & (seen.labels == c)))
            hidden = on_bare & ~on_seen
            for name, c in _HIDERS.items():
                hidden_n[name] += int(np.count_nonzero(hidden & (seen.labels == c)))
    area = pixel_m * pixel_m
    return ({k: n * area for k, n in bare_n.items()}, {k: n * area for k, n in seen_n.items()},
            {k: n * area for k, n in hidden_n.items() if n})
