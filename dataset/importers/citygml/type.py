"""A CityGML building's type, from its geometry: the rows of the lod3 tables.

The Ingolstadt files carry no ``function``/``class`` attributes, so the type is read off the
geometry, in this order:

1. ``with_balconies``: surfaces of class other in front of its covered facades (balconies,
   loggias, railings, bay structures: CityGML ``BuildingInstallation``) hide at least
   :data:`FRONT_HIDDEN_MIN` of their gross area seen straight on
   (:func:`dataset.importers.citygml.visible.hidden_share`);
2. ``terraced``: otherwise, when at least :data:`PARTY_WALL_MIN_M2` of its walls are party
   walls, covered by a neighbour's wall (:func:`dataset.importers.citygml.context.
   party_wall_area_m2`);
3. ``detached``: neither.

Party walls are found against the other buildings of the same import (a ``--citygml``
folder, the preset's files): a building imported alone, or whose neighbour is missing from
the data, counts as detached.
"""

from __future__ import annotations

from typing import Literal

CityGmlType = Literal["with_balconies", "terraced", "detached"]
FRONT_HIDDEN_MIN = 0.02
"""Balconies and the like that hide less than 2 % of the facades are decoration, not a
change of what a camera sees (on the Ingolstadt set: 17 of 49 buildings reach it)."""
PARTY_WALL_MIN_M2 = 10.0
"""A shared wall of at least a storey's height by 3 m. On the Ingolstadt set the shared
area is 0 or at least 53 m², so any value between gives the same split (32 share one)."""


def citygml_building_type(front_hidden_share: float, party_wall_m2: float) -> CityGmlType:
    """The type of a building whose other-class surfaces hide ``front_hidden_share`` of its
    covered facades and whose walls share ``party_wall_m2`` with neighbours (module
    docstring)."""
    if front_hidden_share >= FRONT_HIDDEN_MIN:
        return "with_balconies"
    return "terraced" if party_wall_m2 >= PARTY_WALL_MIN_M2 else "detached"
