"""Which buildings of a CityGML model become scenes, and their surfaces triangulated.

:func:`benchmark_buildings` joins each wall-less ``BuildingPart`` to its building and names
the scenes; :func:`building_surfaces` triangulates a building's polygons
(:mod:`dataset.importers.citygml.polygons`), counting what it repairs; :data:`LABEL_OF_KIND`
is the class each surface kind gets in a mesh. The measured building
(:mod:`dataset.importers.citygml.convert`) and its neighbours
(:mod:`dataset.importers.citygml.context`) are both made from these.
"""

from __future__ import annotations

import re
from collections import Counter
from dataclasses import replace

from dataset.importers.citygml.facades import Surface
from dataset.importers.citygml.files import citygml_stem
from dataset.importers.citygml.polygons import triangulate_polygon
from dataset.importers.citygml.read import CityBuilding, CityModel
from envelope.classes import SemanticClass

_SAFE = re.compile(r"[^A-Za-z0-9_.-]")
LABEL_OF_KIND: dict[str, SemanticClass | None] = {
    "wall": SemanticClass.WALL,
    "roof": SemanticClass.ROOF,
    "window": SemanticClass.WINDOW,
    "door": SemanticClass.DOOR,
    "installation": SemanticClass.OTHER,
    "ground": SemanticClass.OTHER,
    "outer_floor": SemanticClass.OTHER,
    "outer_ceiling": SemanticClass.OTHER,
    "closure": None,  # virtual surfaces close open parts of a model: nothing to see
    "interior": None,  # LoD4 rooms: never seen from outside
}
"""Class of each surface kind in the mesh; None: left out of the mesh."""
def benchmark_buildings(model: CityModel) -> list[CityBuilding]:
    """The buildings of ``model`` that become scenes, their ids made scene names.

    A ``BuildingPart`` without a wall (a stair, a canopy written as a part) joins its
    building as what it is (installations stay "other"), with a warning; a ``Building``
    whose polygons are all in its parts gives no scene itself. A file with one building
    names it after the file (``4018259.xml`` -> ``4018259``); otherwise the ``gml:id``
    (characters other than letters, digits, ``_.-`` become ``_``) names it.
    """
    by_id = {b.gml_id: b for b in model.buildings}
    joined: dict[str, list[CityBuilding]] = {}
    kept = []
    for b in model.buildings:
        has_wall = any(p.kind == "wall" for p in b.polygons)
        if b.is_part and not has_wall and b.parent_id in by_id:
            joined.setdefault(b.parent_id, []).append(b)
        elif b.polygons or not b.is_part and not any(
                c.parent_id == b.gml_id for c in model.buildings):
            kept.append(b)
    out = []
    for b in kept:
        parts = joined.get(b.gml_id, [])
        name = _SAFE.sub("_", citygml_stem(model.path) if len(kept) == 1 else b.gml_id)
        out.append(replace(
            b, gml_id=name if name[:1].isalnum() else f"b{name}",
            polygons=b.polygons + tuple(p for c in parts for p in c.polygons),
            attributes={**b.attributes, "gml:id": b.gml_id},
            warnings=b.warnings + tuple(f"part {c.gml_id}: no WallSurface, joined to its "
                                        "building" for c in parts)))
    return out


def building_surfaces(building: CityBuilding, warnings: Counter) -> list[Surface]:
    """``building``'s polygons triangulated, in file order (file CRS); polygons without area
    are dropped and repairs counted in ``warnings``."""
    surfaces = []
    for p in building.polygons:
        tri = triangulate_polygon(p.rings_m)
        if tri is None:
            warnings["polygon without area dropped"] += 1
            continue
        warnings["non-planar polygon (> 1 cm), triangulated as it stands"] += tri.non_planar
        warnings["self-intersecting polygon, made valid"] += tri.repaired
        surfaces.append(Surface(p.polygon_id, p.kind, p.owner_id, p.rings_m, tri))
    return surfaces
