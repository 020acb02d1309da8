"""An OpenDRIVE road network's lanes as :class:`envelope.neighbours.Street` lines in a
CityGML building's world frame.

The CityGML importer puts a building in its world frame by one shift: ``world = file +
offset_m`` (file CRS metres; ``offset_m`` moves the ground surface's x/y centre to the origin
and its lowest point to z = 0, :mod:`dataset.importers.citygml.convert`). A road network is
mapped the same way: its points (file frame, :mod:`dataset.importers.opendrive.read`) are
transformed from the header's ``geoReference`` to the city model's CRS (pyproj; the
Ingolstadt file's PROJ string is EPSG:32632, the buildings' CRS, so the transform is the
identity), then shifted by the building's ``offset_m``. Heights take the same shift: the
Ingolstadt roads' elevations and the buildings' ground surfaces are in one height system
(the lane point nearest each of the 49 scene buildings lies -0.25 to +2.1 m, median
+0.08 m, above the building's lowest ground point, which is z = 0).
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache
from pathlib import Path

import numpy as np
from pyproj import CRS, Transformer

from dataset.importers.opendrive.read import OpenDriveError, lane_lines, read_opendrive
from envelope.neighbours import Street

DRIVEN_LANES = ("driving",)
"""The lanes a capture vehicle drives in."""


def streets_in_frame(path: str | Path, crs: str, offset_m: Sequence[float],
                     lane_types: tuple[str, ...] = DRIVEN_LANES) -> tuple[Street, ...]:
    """The centre lines of the lanes of ``lane_types`` of the OpenDRIVE file ``path`` in the
    world frame of a building whose file is in ``crs`` and was shifted by ``offset_m`` (3,),
    one :class:`Street` per lane and lane section.

    Raises
    ------
    OpenDriveError
        As :func:`dataset.importers.opendrive.read.read_opendrive`, or a file without a
        ``geoReference`` (it cannot be placed among georeferenced buildings).
    """
    offset = np.asarray(offset_m, dtype=np.float64)
    out = []
    for line in _lines_in_crs(str(Path(path).resolve()), crs, lane_types):
        pts = line[1] + offset
        out.append(Street(line[0], pts))
    return tuple(out)


@lru_cache(maxsize=8)
def _lines_in_crs(path: str, crs: str, lane_types: tuple[str, ...]
                  ) -> tuple[tuple[str, np.ndarray], ...]:
    """(name, (N, 3) points in ``crs``) of each lane line; cached (a preset's buildings share
    one road network)."""
    network = read_opendrive(path)
    if not network.geo_reference:
        raise OpenDriveError(f"{path} has no header geoReference: its roads cannot be placed "
                             f"among buildings in {crs}")
    source, target = CRS.from_user_input(network.geo_reference), CRS.from_user_input(crs)
    move = None if source.equals(target, ignore_axis_order=True) else Transformer.from_crs(
        source, target, always_xy=True)
    out = []
    for line in lane_lines(network, lane_types):
        pts = line.points_m.copy()
        if move is not None:
            pts[:, 0], pts[:, 1] = move.transform(pts[:, 0], pts[:, 1])
        pts.setflags(write=False)
        out.append((f"road {line.road_id} lane {line.lane_id}", pts))
    return tuple(out)
