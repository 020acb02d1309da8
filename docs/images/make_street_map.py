"""The lod3 preset's road network over its buildings: ``python docs/images/make_street_map.py``.

Every shipped CityGML file's ground surfaces (grey; the 49 scene buildings darker) and the
OpenDRIVE lanes (driving lanes blue, sidewalks green), both in EPSG:32632 metres as
:mod:`dataset.importers.opendrive.streets` maps them (offset zero), with one building's
street cameras (red, ``--street`` defaults) to check that the roads run between the houses.
Writes ``docs/images/street_map.png``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from dataset.importers.citygml.preset import (  # noqa: E402
    LOD3_DIR,
    ROAD_NETWORK,
    build_lod3_building,
    lod3_entries,
    lod3_files,
)
from dataset.importers.citygml.read import read_citygml  # noqa: E402
from dataset.importers.opendrive.streets import streets_in_frame  # noqa: E402
from dataset.rendering.street_views import StreetConfig, street_stations  # noqa: E402

EXAMPLE = "4018106"  # the building whose cameras are drawn


def main() -> None:
    scene_files = {LOD3_DIR / e.file for e in lod3_entries()}
    fig, ax = plt.subplots(figsize=(9, 11))
    for f in lod3_files():
        model = read_citygml(f.path)
        for b in model.buildings:
            for p in b.polygons:
                if p.kind == "ground":
                    ring = p.rings_m[0]
                    ax.fill(ring[:, 0], ring[:, 1], lw=0,
                            color="0.35" if f.path in scene_files else "0.7")
    crs = "EPSG:32632"
    for lane, colour in (("sidewalk", "tab:green"), ("driving", "tab:blue")):
        for s in streets_in_frame(ROAD_NETWORK, crs, (0.0, 0.0, 0.0), (lane,)):
            ax.plot(s.points_m[:, 0], s.points_m[:, 1], color=colour, lw=0.6)
    entry = next(e for e in lod3_entries() if e.id == EXAMPLE)
    building = build_lod3_building(entry.id, entry.file)
    offset = np.array(building.truth.extra["offset_m"])
    stations = street_stations(building, StreetConfig())
    ax.plot(stations.positions_m[:, 0] - offset[0], stations.positions_m[:, 1] - offset[1],
            "o", color="tab:red", ms=2.5, label=f"street stations of {EXAMPLE}")
    ax.set_aspect("equal")
    ax.set_xlabel("EPSG:32632 x (m)")
    ax.set_ylabel("EPSG:32632 y (m)")
    ax.set_title("lod3 preset: ground surfaces (scene buildings dark), driving lanes (blue), "
                 "sidewalks (green)", fontsize=9)
    ax.legend(loc="lower left", fontsize=8)
    out = ROOT / "docs" / "images" / "street_map.png"
    fig.savefig(out, dpi=110, bbox_inches="tight")
    print(out)


if __name__ == "__main__":
    main()
