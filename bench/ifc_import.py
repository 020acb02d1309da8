"""IFC import time of a tower of many elements (dataset.examples.ifc_houses.IfcHouse).

    python bench/ifc_import.py --storeys 20 --out /tmp/tower.ifc

Builds a 40 x 16 m tower, 3 m storeys: per storey four 0.3 m outer walls, two interior
walls, a floor slab and 2 x 10 + 2 x 4 windows 1.5 x 1.5 m (each an opening and a window
element), a roof slab on top; then times :func:`dataset.importers.ifc.convert.import_ifc` and prints
the element and face counts with the truth's areas against their closed form.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path[0] = str(Path(__file__).resolve().parent.parent)

from dataset.examples.ifc_houses import IfcHouse  # noqa: E402
from dataset.importers.ifc.convert import import_ifc  # noqa: E402

LX, LY, H, T = 40.0, 16.0, 3.0, 0.3


def tower(path: Path, storeys: int) -> tuple[float, float, int]:
    """Write the tower; returns (facade area, window area, element count) by hand."""
    h = IfcHouse()
    h.storey("ground", 0.0)
    n_windows = 0
    for k in range(storeys):
        z0, z1 = k * H, (k + 1) * H
        south = h.box("IfcWall", (0, 0, z0), (LX, T, z1))
        north = h.box("IfcWall", (0, LY - T, z0), (LX, LY, z1))
        west = h.box("IfcWall", (0, T, z0), (T, LY - T, z1))
        east = h.box("IfcWall", (LX - T, T, z0), (LX, LY - T, z1))
        h.box("IfcWall", (LX / 2, T, z0), (LX / 2 + 0.15, LY - T, z1))
        h.box("IfcWall", (T, LY / 2, z0), (LX / 2, LY / 2 + 0.15, z1))
        h.box("IfcSlab", (T, T, z1 - 0.25), (LX - T, LY - T, z1), predefined_type="FLOOR")
        for i in range(10):
            x = 1.5 + 4.0 * i
            h.fill(south, "IfcWindow", (x, -0.01, z0 + 0.9), (x + 1.5, T + 0.01, z0 + 2.4), axis=1)
            h.fill(north, "IfcWindow", (x, LY - T - 0.01, z0 + 0.9), (x + 1.5, LY + 0.01, z0 + 2.4),
                   axis=1)
        for i in range(4):
            y = 1.5 + 3.5 * i
            h.fill(west, "IfcWindow", (-0.01, y, z0 + 0.9), (T + 0.01, y + 1.5, z0 + 2.4), axis=0)
            h.fill(east, "IfcWindow", (LX - T - 0.01, y, z0 + 0.9), (LX + 0.01, y + 1.5, z0 + 2.4),
                   axis=0)
        n_windows += 28
    h.box("IfcSlab", (0, 0, storeys * H), (LX, LY, storeys * H + 0.3), predefined_type="ROOF")
    h.write(path)
    return 2 * (LX + LY) * storeys * H, n_windows * 1.5 * 1.5, len(h.file.by_type("IfcElement"))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--storeys", type=int, default=20)
    p.add_argument("--out", type=Path, default=Path("/tmp/tower.ifc"))
    args = p.parse_args()
    start = time.perf_counter()
    facade, window, elements = tower(args.out, args.storeys)
    print(f"wrote {args.out}: {elements} elements in {time.perf_counter() - start:.1f} s")
    start = time.perf_counter()
    building = import_ifc(args.out)
    took = time.perf_counter() - start
    t = building.truth
    print(f"imported in {took:.1f} s: {len(building.mesh.faces)} faces, {len(t.facades)} facades;"
          f" facade {t.facade_area_m2:.2f} m2 (by hand {facade:.2f}), window "
          f"{t.window_area_m2:.2f} m2 (by hand {window:.2f}), footprint "
          f"{t.footprint_area_m2:.2f} m2 (by hand {LX * LY:.2f})")


if __name__ == "__main__":
    main()
