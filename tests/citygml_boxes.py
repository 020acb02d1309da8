"""Small CityGML 2.0 files of box buildings, for closed-form tests of the CityGML importer.

Each building is an axis-aligned box (walls, flat roof, ground) with, optionally, windows on
its front wall (the wall facing -y) and a plate standing in front of that wall (a
``BuildingInstallation``, like a balcony's parapet). Coordinates are UTM 32N metres near
Ingolstadt so the CRS and north are those of the real files.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

X0, Y0 = 677000.0, 5403000.0  # EPSG:32632, Ingolstadt


@dataclass(frozen=True)
class Box:
    """A box building: ``name``, x/y extent (metres from X0, Y0), height; windows on the front
    (y = y_min) wall as (x_min, z_min, x_max, z_max); a plate (x_min, x_max, z_min, z_max,
    distance in front of the wall); X3D diffuse colour of its walls."""

    name: str
    x: tuple[float, float]
    y: tuple[float, float]
    height: float
    windows: tuple[tuple[float, float, float, float], ...] = ()
    plate: tuple[float, float, float, float, float] | None = None
    wall_rgb: tuple[float, float, float] | None = None
    window_texture: str | None = None
    extra: dict = field(default_factory=dict)


def write_boxes(path: Path, boxes: list[Box]) -> Path:
    """Write ``boxes`` as one CityGML 2.0 file at ``path``; return it."""
    members, looks = [], []
    for b in boxes:
        members.append(_building(b, looks))
    text = f"""<?xml version="1.0" encoding="UTF-8"?>
<core:CityModel xmlns:core="http://www.opengis.net/citygml/2.0"
 xmlns:bldg="http://www.opengis.net/citygml/building/2.0"
 xmlns:app="http://www.opengis.net/citygml/appearance/2.0"
 xmlns:gml="http://www.opengis.net/gml" xmlns:xlink="http://www.w3.org/1999/xlink">
<gml:boundedBy><gml:Envelope srsName="EPSG:32632" srsDimension="3">
<gml:lowerCorner>{X0} {Y0} 0</gml:lowerCorner>
<gml:upperCorner>{X0 + 100} {Y0 + 100} 30</gml:upperCorner>
</gml:Envelope></gml:boundedBy>
{''.join(members)}
<app:appearanceMember><app:Appearance><app:theme>test</app:theme>
{''.join(looks)}
</app:Appearance></app:appearanceMember>
</core:CityModel>
"""
    path.write_text(text)
    return path


def _pos(points) -> str:
    pts = [*points, points[0]]
    return " ".join(f"{X0 + x:.3f} {Y0 + y:.3f} {z:.3f}" for x, y, z in pts)


def _polygon(pid: str, ring, holes=()) -> str:
    inner = "".join(f'<gml:interior><gml:LinearRing gml:id="{pid}_h{k}"><gml:posList>'
                    f"{_pos(h)}</gml:posList></gml:LinearRing></gml:interior>"
                    for k, h in enumerate(holes))
    return (f'<gml:surfaceMember><gml:Polygon gml:id="{pid}"><gml:exterior>'
            f'<gml:LinearRing gml:id="{pid}_r"><gml:posList>{_pos(ring)}</gml:posList>'
            f"</gml:LinearRing></gml:exterior>{inner}</gml:Polygon></gml:surfaceMember>")


def _surface(kind: str, sid: str, polygons: str, openings: str = "") -> str:
    return (f'<bldg:boundedBy><bldg:{kind} gml:id="{sid}"><bldg:lod3MultiSurface>'
            f"<gml:MultiSurface>{polygons}</gml:MultiSurface></bldg:lod3MultiSurface>"
            f"{openings}</bldg:{kind}></bldg:boundedBy>")


def _building(b: Box, looks: list[str]) -> str:
    (x0, x1), (y0, y1), h = b.x, b.y, b.height
    n = b.name
    # Rings counter-clockwise seen from outside.
    front_holes = [[(wx0, y0, wz0), (wx0, y0, wz1), (wx1, y0, wz1), (wx1, y0, wz0)]
                   for wx0, wz0, wx1, wz1 in b.windows]
    walls = {
        "front": [(x0, y0, 0), (x1, y0, 0), (x1, y0, h), (x0, y0, h)],
        "right": [(x1, y0, 0), (x1, y1, 0), (x1, y1, h), (x1, y0, h)],
        "back": [(x1, y1, 0), (x0, y1, 0), (x0, y1, h), (x1, y1, h)],
        "left": [(x0, y1, 0), (x0, y0, 0), (x0, y0, h), (x0, y1, h)],
    }
    parts = []
    for side, ring in walls.items():
        openings = ""
        if side == "front":
            for k, (wx0, wz0, wx1, wz1) in enumerate(b.windows):
                glass = [(wx0, y0, wz0), (wx1, y0, wz0), (wx1, y0, wz1), (wx0, y0, wz1)]
                openings += (f'<bldg:opening><bldg:Window gml:id="{n}_win{k}">'
                             f"<bldg:lod3MultiSurface><gml:MultiSurface>"
                             f"{_polygon(f'{n}_glass{k}', glass)}</gml:MultiSurface>"
                             f"</bldg:lod3MultiSurface></bldg:Window></bldg:opening>")
                if b.window_texture:
                    looks.append(
                        f"<app:surfaceDataMember><app:ParameterizedTexture><app:imageURI>"
                        f"{b.window_texture}</app:imageURI><app:wrapMode>wrap</app:wrapMode>"
                        f'<app:target uri="#{n}_glass{k}"><app:TexCoordList>'
                        f'<app:textureCoordinates ring="#{n}_glass{k}_r">0 0 1 0 1 1 0 1 0 0'
                        f"</app:textureCoordinates></app:TexCoordList></app:target>"
                        f"</app:ParameterizedTexture></app:surfaceDataMember>")
        holes = front_holes if side == "front" else ()
        parts.append(_surface("WallSurface", f"{n}_{side}",
                              _polygon(f"{n}_{side}_p", ring, holes), openings))
        if b.wall_rgb is not None:
            rgb = " ".join(str(c) for c in b.wall_rgb)
            looks.append(f"<app:surfaceDataMember><app:X3DMaterial><app:diffuseColor>{rgb}"
                         f"</app:diffuseColor><app:target>#{n}_{side}_p</app:target>"
                         f"</app:X3DMaterial></app:surfaceDataMember>")
    parts.append(_surface("RoofSurface", f"{n}_roof", _polygon(
        f"{n}_roof_p", [(x0, y0, h), (x1, y0, h), (x1, y1, h), (x0, y1, h)])))
    parts.append(_surface("GroundSurface", f"{n}_ground", _polygon(
        f"{n}_ground_p", [(x0, y0, 0), (x0, y1, 0), (x1, y1, 0), (x1, y0, 0)])))
    install = ""
    if b.plate is not None:
        px0, px1, pz0, pz1, d = b.plate
        front = [(px0, y0 - d, pz0), (px1, y0 - d, pz0), (px1, y0 - d, pz1), (px0, y0 - d, pz1)]
        install = (f'<bldg:outerBuildingInstallation><bldg:BuildingInstallation gml:id="{n}_bal">'
                   f"<bldg:lod3Geometry><gml:MultiSurface>{_polygon(f'{n}_plate', front)}"
                   f"</gml:MultiSurface></bldg:lod3Geometry></bldg:BuildingInstallation>"
                   f"</bldg:outerBuildingInstallation>")
    return (f'<core:cityObjectMember><bldg:Building gml:id="{n}">{"".join(parts)}{install}'
            f"</bldg:Building></core:cityObjectMember>")
