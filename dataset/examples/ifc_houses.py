"""Small IFC buildings made with ``ifcopenshell.api``, with their areas by hand.

``python -m dataset.examples.ifc_houses --out DIR`` writes the five houses of
:data:`HOUSES` as ``DIR/<name>.ifc`` (the tests build them on the fly). Every solid is an
axis-aligned box (an extruded rectangle, as BIM tools write walls and slabs); windows and
doors fill openings cut through their wall. Lengths are given in metres and written in the
file's unit (millimetres or metres).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import ifcopenshell
import ifcopenshell.api
import ifcopenshell.api.aggregate
import ifcopenshell.api.context
import ifcopenshell.api.feature
import ifcopenshell.api.geometry
import ifcopenshell.api.project
import ifcopenshell.api.root
import ifcopenshell.api.spatial
import ifcopenshell.api.unit
import numpy as np

Vec = tuple[float, float, float]


class IfcHouse:
    """An IFC4 file with one site, one building and its storeys, built box by box."""

    def __init__(self, *, millimetres: bool = False, origin: Vec = (0.0, 0.0, 0.0)):
        api = ifcopenshell.api
        self.origin = np.asarray(origin, dtype=np.float64)  # where (0, 0, 0) of the plan lies
        self.file = api.project.create_file(version="IFC4")
        f = self.file
        project = api.root.create_entity(f, ifc_class="IfcProject", name="test project")
        if millimetres:
            api.unit.assign_unit(f, units=[api.unit.add_si_unit(f, unit_type="LENGTHUNIT",
                                                                prefix="MILLI")])
        else:
            api.unit.assign_unit(f, units=[api.unit.add_si_unit(f, unit_type="LENGTHUNIT")])
        self.scale = 1000.0 if millimetres else 1.0  # file units per metre
        model = api.context.add_context(f, context_type="Model")
        self.body = api.context.add_context(f, context_type="Model", context_identifier="Body",
                                            target_view="MODEL_VIEW", parent=model)
        site = api.root.create_entity(f, ifc_class="IfcSite", name="site")
        self.building = api.root.create_entity(f, ifc_class="IfcBuilding", name="house")
        api.aggregate.assign_object(f, products=[site], relating_object=project)
        api.aggregate.assign_object(f, products=[self.building], relating_object=site)
        self.storeys: dict[str, ifcopenshell.entity_instance] = {}

    def storey(self, name: str, elevation_m: float) -> ifcopenshell.entity_instance:
        api, f = ifcopenshell.api, self.file
        s = api.root.create_entity(f, ifc_class="IfcBuildingStorey", name=name)
        s.Elevation = (self.origin[2] + elevation_m) * self.scale
        api.geometry.edit_object_placement(
            f, product=s, matrix=_translation(self.origin + (0, 0, elevation_m)))
        api.aggregate.assign_object(f, products=[s], relating_object=self.building)
        self.storeys[name] = s
        return s

    def box(self, ifc_class: str, lo: Vec, hi: Vec, *, storey: str = "ground",
            parent: ifcopenshell.entity_instance | None = None, predefined_type: str | None = None,
            name: str | None = None) -> ifcopenshell.entity_instance:
        """An element whose body is the box [lo, hi] (metres, world frame)."""
        api, f = ifcopenshell.api, self.file
        e = api.root.create_entity(f, ifc_class=ifc_class, name=name or ifc_class,
                                   predefined_type=predefined_type)
        size = np.subtract(hi, lo)
        rep = api.geometry.add_wall_representation(
            f, context=self.body, length=float(size[0]), thickness=float(size[1]),
            height=float(size[2]))
        api.geometry.assign_representation(f, product=e, representation=rep)
        api.geometry.edit_object_placement(f, product=e, matrix=_translation(self.origin + lo))
        if parent is not None:
            api.aggregate.assign_object(f, products=[e], relating_object=parent)
        elif ifc_class != "IfcOpeningElement":
            api.spatial.assign_container(f, products=[e], relating_structure=self.storeys[storey])
        return e

    def fill(self, wall: ifcopenshell.entity_instance, ifc_class: str, lo: Vec, hi: Vec, *,
             axis: int, pane_m: float = 0.06) -> ifcopenshell.entity_instance:
        """Cut the opening [lo, hi] through ``wall`` (``axis``: the wall's thickness axis, 0 or
        1) and fill it with a ``pane_m`` thick window or door in the middle of the wall."""
        api, f = ifcopenshell.api, self.file
        opening = self.box("IfcOpeningElement", lo, hi)
        api.feature.add_feature(f, feature=opening, element=wall)
        mid = (lo[axis] + hi[axis]) / 2
        plo, phi = list(lo), list(hi)
        plo[axis], phi[axis] = mid - pane_m / 2, mid + pane_m / 2
        element = self.box(ifc_class, tuple(plo), tuple(phi))
        api.feature.add_filling(f, opening=opening, element=element)
        width = hi[1 - axis] - lo[1 - axis]
        element.OverallWidth = width * self.scale
        element.OverallHeight = (hi[2] - lo[2]) * self.scale
        return element

    def write(self, path: Path) -> Path:
        self.file.write(str(path))
        return path


def _translation(xyz) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = xyz
    return m


# --- the test buildings: (file, ground truth by hand) ---------------------------------------

def box_house(path: Path, *, millimetres: bool = True, windows: bool = True,
              origin: Vec = (0.0, 0.0, 0.0)) -> dict:
    """10 x 8 m, walls 0.3 m thick and 3 m high on z = 0, a roof slab, no floor slab (an open
    underside): two 1.2 x 1.5 m windows south, one east, a 1 x 2.1 m door north; ``origin``
    moves it (a georeferenced model)."""
    h = IfcHouse(millimetres=millimetres, origin=origin)
    h.storey("ground", 0.0)
    south = h.box("IfcWall", (0, 0, 0), (10, 0.3, 3), name="south")
    north = h.box("IfcWall", (0, 7.7, 0), (10, 8, 3), name="north")
    h.box("IfcWall", (0, 0.3, 0), (0.3, 7.7, 3), name="west")
    east = h.box("IfcWall", (9.7, 0.3, 0), (10, 7.7, 3), name="east")
    h.box("IfcSlab", (0, 0, 3), (10, 8, 3.2), predefined_type="ROOF", name="roof")
    window, door = 0.0, 0.0
    if windows:
        for x0 in (2.0, 6.0):
            h.fill(south, "IfcWindow", (x0, -0.01, 0.9), (x0 + 1.2, 0.31, 2.4), axis=1)
        h.fill(east, "IfcWindow", (9.69, 3.0, 0.9), (10.01, 4.2, 2.4), axis=0)
        h.fill(north, "IfcDoor", (4.5, 7.69, 0.0), (5.5, 8.01, 2.1), axis=1)
        window, door = 3 * 1.2 * 1.5, 1.0 * 2.1
    h.write(path)
    return {"gross": 2 * (10 + 8) * 3.0, "window": window, "door": door, "footprint": 80.0,
            "outline": [(0, 0), (10, 0), (10, 8), (0, 8)], "facades": 4, "height": 3.2,
            "origin": origin}


def l_shaped_house(path: Path) -> dict:
    """An L (12 x 6 m plus 6 x 4 m to the north of its west end), two storeys, 6 m walls
    0.25 m thick, interior walls, an intermediate floor slab overlapping them, roof slabs;
    six 1.5 x 1.2 m windows south, two west."""
    h = IfcHouse(millimetres=False)
    h.storey("ground", 0.0)
    h.storey("first", 3.0)
    south = h.box("IfcWall", (0, 0, 0), (12, 0.25, 6))
    h.box("IfcWall", (11.75, 0.25, 0), (12, 6, 6))
    h.box("IfcWall", (5.75, 5.75, 0), (11.75, 6, 6))
    h.box("IfcWall", (5.75, 6, 0), (6, 9.75, 6))
    h.box("IfcWall", (0, 9.75, 0), (6, 10, 6))
    west = h.box("IfcWall", (0, 0.25, 0), (0.25, 9.75, 6))
    h.box("IfcWall", (0.25, 4, 0), (5.75, 4.15, 6), name="partition")
    h.box("IfcWall", (5, 4.15, 0), (5.15, 9.75, 6), name="partition")
    h.box("IfcSlab", (0.25, 0.25, 2.8), (11.75, 5.75, 3.0), predefined_type="FLOOR")
    h.box("IfcSlab", (0.25, 5.75, 2.8), (5.75, 9.75, 3.0), predefined_type="FLOOR")
    h.box("IfcSlab", (0, 0, 6), (12, 6, 6.2), predefined_type="ROOF")
    h.box("IfcSlab", (0, 6, 6), (6, 10, 6.2), predefined_type="ROOF")
    for z0 in (1.0, 4.0):
        for x0 in (2.0, 5.5, 9.0):
            h.fill(south, "IfcWindow", (x0, -0.01, z0), (x0 + 1.5, 0.26, z0 + 1.2), axis=1)
        h.fill(west, "IfcWindow", (-0.01, 7.0, z0), (0.26, 8.5, z0 + 1.2), axis=0)
    h.write(path)
    return {"gross": 44 * 6.0, "window": 8 * 1.8, "door": 0.0, "footprint": 96.0,
            "outline": [(0, 0), (12, 0), (12, 6), (6, 6), (6, 10), (0, 10)], "facades": 6,
            "height": 6.2}


def crawl_space_house(path: Path) -> dict:
    """The box house on 1 m foundation walls below grade, under a floor slab (top at z = 0)
    that closes the crawl space from above; grade is the ground storey's floor, z = 0."""
    box_house(path, millimetres=True)
    h = IfcHouse.__new__(IfcHouse)
    h.file = ifcopenshell.open(str(path))
    h.scale, h.origin = 1000.0, np.zeros(3)
    h.body = h.file.by_type("IfcGeometricRepresentationSubContext")[0]
    h.storeys = {"ground": h.file.by_type("IfcBuildingStorey")[0]}
    for lo, hi in (((0, 0, -1), (10, 0.3, 0)), ((0, 7.7, -1), (10, 8, 0)),
                   ((0, 0.3, -1), (0.3, 7.7, 0)), ((9.7, 0.3, -1), (10, 7.7, 0))):
        h.box("IfcWall", lo, hi, name="foundation wall")
    h.box("IfcSlab", (0.3, 0.3, -0.2), (9.7, 7.7, 0), predefined_type="FLOOR")
    h.write(path)
    return {"gross": 2 * (10 + 8) * 3.0, "window": 3 * 1.8, "door": 2.1, "footprint": 80.0,
            "outline": [(0, 0), (10, 0), (10, 8), (0, 8)], "facades": 4, "height": 3.2}


def curtain_wall_house(path: Path) -> dict:
    """The box house with a 10 x 3 m curtain wall as its south side: five 0.1 m mullions,
    transoms at the foot and head, four glass plates 2.8 m high between them."""
    h = IfcHouse(millimetres=True)
    h.storey("ground", 0.0)
    h.box("IfcWall", (0, 7.7, 0), (10, 8, 3))
    h.box("IfcWall", (0, 0.15, 0), (0.3, 7.7, 3))
    h.box("IfcWall", (9.7, 0.15, 0), (10, 7.7, 3))
    h.box("IfcSlab", (0, 0, 3), (10, 8, 3.2), predefined_type="ROOF")
    cw = h.box("IfcCurtainWall", (0, 0, 0), (10, 0.15, 3))
    cw.Representation = None  # the parts carry the geometry
    mullions = [0.0, 2.45, 4.95, 7.45, 9.9]
    for x0 in mullions:
        h.box("IfcMember", (x0, 0, 0), (x0 + 0.1, 0.15, 3), parent=cw)
    glass = 0.0
    for a, b in zip(mullions[:-1], mullions[1:]):
        lo, hi = a + 0.1, b
        h.box("IfcMember", (lo, 0, 0), (hi, 0.15, 0.1), parent=cw)
        h.box("IfcMember", (lo, 0, 2.9), (hi, 0.15, 3.0), parent=cw)
        h.box("IfcPlate", (lo, 0.065, 0.1), (hi, 0.085, 2.9), parent=cw)
        glass += (hi - lo) * 2.8
    h.write(path)
    return {"gross": 2 * (10 + 8) * 3.0, "window": glass, "door": 0.0, "footprint": 80.0,
            "outline": [(0, 0), (10, 0), (10, 8), (0, 8)], "facades": 4, "height": 3.2}


def no_window_house(path: Path) -> dict:
    """The box house without windows or door: WWR 0."""
    return box_house(path, millimetres=False, windows=False)


HOUSES = {"box_mm": box_house, "l_shaped": l_shaped_house, "crawl_space": crawl_space_house,
          "curtain_wall": curtain_wall_house, "no_windows": no_window_house}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m dataset.examples.ifc_houses",
        description="Write the example IFC houses (box in millimetres, L-shaped, crawl space, "
                    "curtain wall, no windows) into a folder; their areas are in the docstrings.")
    parser.add_argument("--out", type=Path, required=True, help="folder for <name>.ifc")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    for name, make in HOUSES.items():
        expected = make(args.out / f"{name}.ifc")
        print(f"{args.out / name}.ifc: facade {expected['gross']:.2f} m2, window "
              f"{expected['window']:.2f} m2, WWR {expected['window'] / expected['gross']:.4f}, "
              f"footprint {expected['footprint']:.2f} m2")
    return 0


if __name__ == "__main__":
    sys.exit(main())
