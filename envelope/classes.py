"""Semantic class ids shared by every part of the project (docs/DESIGN.md).

Ids 0-3 match the public BuildNet3D generator. The facade classes (wall, window,
door) make up the gross facade area; roof and other never count as facade.
"""

from __future__ import annotations

from enum import IntEnum


class SemanticClass(IntEnum):
    BACKGROUND = 0  # sky, environment, anything not the building
    WALL = 1  # opaque facade surface
    WINDOW = 2  # glazing incl. frame and the reveal of its opening
    ROOF = 3
    DOOR = 4
    OTHER = 5  # balconies, railings, chimneys, decoration


NUM_CLASSES = len(SemanticClass)
CLASS_RGB: tuple[tuple[int, int, int], ...] = (
    (0, 0, 0), (200, 200, 200), (40, 110, 230), (170, 60, 50), (140, 90, 40), (60, 160, 70),
)
"""Display colour (RGB, 0-255) of each class id, in id order: the one palette of figures,
debug images and the HTML report."""
UNKNOWN_CLASS_RGB = (255, 0, 255)
"""Display colour of an id beyond the known classes: it stands out."""
CLASS_NAMES: tuple[str, ...] = tuple(c.name.lower() for c in SemanticClass)
FACADE_CLASSES: tuple[SemanticClass, ...] = (
    SemanticClass.WALL,
    SemanticClass.WINDOW,
    SemanticClass.DOOR,
)
NO_FACADE = 0
"""Facade id of a face or pixel that belongs to no facade (roof, reveals, balconies, sky).

Real facades are numbered from 1, so facade-id images store ids directly with 0 = none.
"""


def class_id_from_name(name: str) -> SemanticClass:
    """Map a class name (case-insensitive, e.g. ``"Window"``) to its id.

    Raises
    ------
    ValueError
        If the name is not one of :data:`CLASS_NAMES`.
    """
    key = name.strip().lower()
    if key not in CLASS_NAMES:
        raise ValueError(
            f"unknown semantic class name {name!r}; expected one of {', '.join(CLASS_NAMES)}"
        )
    return SemanticClass(CLASS_NAMES.index(key))
