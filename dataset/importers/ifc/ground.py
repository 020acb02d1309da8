"""Where the ground is in an IFC model: the storey at grade, from what the model says.

IFC has no terrain line, and many models have storeys below grade (a foundation storey
at -1.25 m, a basement). The ground is, in order:

1. the lowest storey flagged ``AboveGround`` (or the one flagged ``EntranceLevel``) in
   ``Pset_BuildingStoreyCommon``, when the model sets the flag;
2. the building's ``ElevationOfTerrain`` (both it and ``ElevationOfRefHeight``, the datum's
   elevation, are heights above sea level: the ground is their difference above the datum),
   when both are given;
3. the storey nearest the building's own datum (its placement's height, the +-0.00 that
   architects put at the ground floor): a foundation storey at -1.25 m is below grade,
   a ground floor at -0.60 m (a raised-floor datum) is the ground.

Storeys below the ground are reported by name; ``--ground-z`` overrides the rule.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class GroundLevel:
    """The ground of an IFC model: world ``z_m`` (metres), the storey it is (if any), why
    it was chosen, and every storey below it (name, world z in metres)."""

    z_m: float
    storey: str | None
    reason: str
    below: tuple[tuple[str, float], ...]


def ground_level(model, unit_scale: float) -> GroundLevel | None:
    """The model's ground (module docstring), None for a model without storeys."""
    import ifcopenshell.util.element as element_util
    import ifcopenshell.util.placement as placement

    storeys = []
    for s in model.by_type("IfcBuildingStorey"):
        if s.ObjectPlacement is None:
            continue
        z = float(placement.get_local_placement(s.ObjectPlacement)[2, 3]) * unit_scale
        flags = element_util.get_pset(s, "Pset_BuildingStoreyCommon") or {}
        storeys.append((z, s.Name or s.GlobalId, flags.get("AboveGround"),
                        flags.get("EntranceLevel")))
    if not storeys:
        return None
    storeys.sort(key=lambda s: s[0])
    entrance = [s for s in storeys if s[3] is True]
    above = [s for s in storeys if s[2] is True]
    if entrance:
        chosen, reason = entrance[0], "its storey flagged EntranceLevel"
    elif above:
        chosen, reason = above[0], "the lowest storey flagged AboveGround"
    else:
        datum, terrain = _building_datum_m(model, unit_scale)
        if terrain is not None:
            below = tuple((name, z) for z, name, *_ in storeys if z < terrain - 1e-6)
            return GroundLevel(terrain, None, "the building's ElevationOfTerrain", below)
        chosen = min(storeys, key=lambda s: (abs(s[0] - datum), s[0]))
        reason = "the storey nearest the building's datum (+-0.00)"
    below = tuple((name, z) for z, name, *_ in storeys if z < chosen[0] - 1e-6)
    return GroundLevel(chosen[0], chosen[1], reason, below)


def _building_datum_m(model, unit_scale: float) -> tuple[float, float | None]:
    """World z of the (first) building's placement (its datum), and of the terrain when
    both ElevationOfTerrain and ElevationOfRefHeight are set."""
    import ifcopenshell.util.placement as placement

    buildings = model.by_type("IfcBuilding")
    if not buildings or buildings[0].ObjectPlacement is None:
        return 0.0, None
    b = buildings[0]
    datum = float(placement.get_local_placement(b.ObjectPlacement)[2, 3]) * unit_scale
    terrain = getattr(b, "ElevationOfTerrain", None)
    reference = getattr(b, "ElevationOfRefHeight", None)
    if terrain is None or reference is None:
        return datum, None
    return datum, datum + (float(terrain) - float(reference)) * unit_scale
