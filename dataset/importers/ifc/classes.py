"""Which of our classes an IFC element is (wall, window, door, roof, other), or no geometry.

The default mapping (:data:`ENTITY_CLASSES`, :data:`NOT_GEOMETRY`, and two context rules)
can be overridden by a small JSON file, keyed by entity name (``"IfcRailing"``, applies to
subtypes too) or by an element's GlobalId, valued by a class name or ``"skip"``::

    {"IfcCovering": "wall", "IfcRailing": "skip", "2O2Fr$t4X7Zf8NOew3FLOH": "window"}
"""

from __future__ import annotations

import json
from pathlib import Path

from envelope.classes import CLASS_NAMES, SemanticClass

SKIP = "skip"
ENTITY_CLASSES: dict[str, SemanticClass] = {
    "IfcWall": SemanticClass.WALL,  # and its subtypes IfcWallStandardCase, IfcWallElementedCase
    "IfcCurtainWall": SemanticClass.WALL,
    "IfcWindow": SemanticClass.WINDOW,
    "IfcDoor": SemanticClass.DOOR,
    "IfcRoof": SemanticClass.ROOF,
}
"""Entity -> class; an entity not listed (nor a subtype of one listed) is ``other``."""
NOT_GEOMETRY = (
    "IfcSpatialElement",  # sites, buildings, storeys, spaces, zones (IFC4)
    "IfcSpatialStructureElement",  # the same in IFC2X3
    "IfcSpace",
    "IfcOpeningElement",
    "IfcFurnishingElement",
    "IfcVirtualElement",
    "IfcAnnotation",
    "IfcGrid",
    "IfcDistributionPort",
)
"""Products that are no part of the building's envelope and are not imported (subtypes too)."""
EXTERNAL_FLAGS: dict[str, str] = {"IfcWall": "Pset_WallCommon", "IfcDoor": "Pset_DoorCommon"}
"""Entity -> property set whose ``IsExternal`` tells an outer element from an interior one."""


def read_class_overrides(path: str | Path) -> dict[str, SemanticClass | str]:
    """The overrides in a JSON file: key (entity name or GlobalId) -> class or :data:`SKIP`.

    Raises
    ------
    ValueError
        Unreadable file, not a JSON object, or a value that names no class.
    """
    path = Path(path)
    try:
        raw = json.loads(path.read_text())
    except (OSError, ValueError) as exc:
        raise ValueError(f"cannot read the class mapping {path}: {exc}") from exc
    if not isinstance(raw, dict):
        raise ValueError(f"{path}: the class mapping must be a JSON object "
                         '{"IfcEntity or GlobalId": "class name or skip"}')
    out: dict[str, SemanticClass | str] = {}
    names = [*CLASS_NAMES[1:], SKIP]
    for key, value in raw.items():
        v = str(value).strip().lower()
        if v not in names:
            raise ValueError(f"{path}: {key!r} maps to {value!r}; use one of {', '.join(names)}")
        out[str(key)] = SKIP if v == SKIP else SemanticClass(CLASS_NAMES.index(v))
    return out


def interior_flagged_entities(model) -> frozenset[str]:
    """The entities of :data:`EXTERNAL_FLAGS` whose ``IsExternal`` the model sets both ways.

    Only there does ``IsExternal = False`` tell an interior element: some exporters set it
    False on every element (a Revit export in the corpus does, windows included).
    """
    from ifcopenshell.util.element import get_pset

    out = set()
    for entity, pset in EXTERNAL_FLAGS.items():
        values = {get_pset(e, pset, "IsExternal") for e in model.by_type(entity)}
        if True in values and False in values:
            out.add(entity)
    return frozenset(out)


def class_of_element(element, overrides: dict[str, SemanticClass | str] | None = None,
                     interior_flagged: frozenset[str] = frozenset()) -> SemanticClass | str:
    """Our class of an IFC product, or :data:`SKIP` for one that is not imported.

    Order: an override by GlobalId, by entity (the most specific listed supertype wins);
    products in :data:`NOT_GEOMETRY`; a plate of a curtain wall is window and its other
    parts (members) wall; a slab of type ROOF is roof; a wall or door of an entity in
    ``interior_flagged`` (:func:`interior_flagged_entities`) whose ``IsExternal`` is False
    is other (an interior partition or door is no facade); :data:`ENTITY_CLASSES`; a part
    of an aggregate (a roof's slabs, a wall's parts) takes the class of its whole; else
    other.
    """
    overrides = overrides or {}
    if element.GlobalId in overrides:
        return overrides[element.GlobalId]
    for entity in _supertypes(element):
        if entity in overrides:
            return overrides[entity]
    if any(element.is_a(e) for e in NOT_GEOMETRY):
        return SKIP
    whole = _aggregate_parent(element)
    if whole is not None and whole.is_a("IfcCurtainWall"):
        return SemanticClass.WINDOW if element.is_a("IfcPlate") else SemanticClass.WALL
    if element.is_a("IfcSlab") and getattr(element, "PredefinedType", None) == "ROOF":
        return SemanticClass.ROOF
    for entity in interior_flagged:
        if element.is_a(entity) and _is_external(element, EXTERNAL_FLAGS[entity]) is False:
            return SemanticClass.OTHER
    for entity, cls in ENTITY_CLASSES.items():
        if element.is_a(entity):
            return cls
    if whole is not None and not any(whole.is_a(e) for e in NOT_GEOMETRY):
        return class_of_element(whole, overrides, interior_flagged)
    return SemanticClass.OTHER


def _is_external(element, pset: str) -> bool | None:
    from ifcopenshell.util.element import get_pset

    return get_pset(element, pset, "IsExternal")


def _supertypes(element) -> list[str]:
    """The element's entity and its supertypes, most specific first."""
    out, decl = [], element.wrapped_data.declaration().as_entity()
    while decl is not None:
        out.append(decl.name())
        decl = decl.supertype()
    return out


def _aggregate_parent(element):
    for rel in getattr(element, "Decomposes", None) or ():
        if rel.is_a("IfcRelAggregates"):
            return rel.RelatingObject
    return None
