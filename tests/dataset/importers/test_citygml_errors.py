"""Bad CityGML input: a clear error naming the element (``gml:id``), or a counted repair.

Each case edits a copy of a real file (tests/fixtures/citygml/4018259.xml.xz) in a
temporary folder.
"""

from __future__ import annotations

import lzma
from pathlib import Path

import numpy as np
import pytest
from lxml import etree
from paths import FIXTURES

from dataset.importers.citygml.convert import import_citygml
from dataset.importers.citygml.files import CityGmlError
from dataset.importers.citygml.read import read_citygml

FIXTURE = FIXTURES / "citygml" / "4018259.xml.xz"


def _tree() -> etree._ElementTree:
    with lzma.open(FIXTURE) as fh:
        return etree.parse(fh)


def _write(tmp_path: Path, tree, name: str = "edited.gml") -> Path:
    path = tmp_path / name
    tree.write(str(path), xml_declaration=True, encoding="utf-8")
    return path


def _polygon(tree, kind: str, index: int = 0):
    """The ``index``-th gml:Polygon under a ``kind`` element (e.g. "WallSurface")."""
    return [p for el in tree.getroot().iter(f"{{*}}{kind}")
            for p in el.iter("{*}Polygon")][index]


def _set_ring(polygon, points: np.ndarray) -> str:
    pos = polygon.find(".//{*}exterior//{*}posList")
    pos.text = " ".join(f"{x:.6f}" for x in np.asarray(points).reshape(-1))
    return pos.getparent().get("{http://www.opengis.net/gml}id")


def _ring(polygon) -> np.ndarray:
    pos = polygon.find(".//{*}exterior//{*}posList")
    return np.asarray(pos.text.split(), dtype=float).reshape(-1, 3)


def test_truncated_xml(tmp_path):
    text = lzma.decompress(FIXTURE.read_bytes())
    path = tmp_path / "cut.gml"
    path.write_bytes(text[: len(text) // 2])
    with pytest.raises(CityGmlError, match="not well-formed XML.*truncated"):
        read_citygml(path)
    cut_xz = tmp_path / "cut.gml.xz"
    cut_xz.write_bytes(FIXTURE.read_bytes()[:3000])
    with pytest.raises(CityGmlError, match="not well-formed"):
        read_citygml(cut_xz)


def test_not_citygml(tmp_path):
    path = tmp_path / "page.xml"
    path.write_text("<html><body>not a city model</body></html>")
    with pytest.raises(CityGmlError, match="is not CityGML 2.0 or 3.0.*html"):
        read_citygml(path)


def test_missing_file(tmp_path):
    with pytest.raises(CityGmlError, match="does not exist"):
        read_citygml(tmp_path / "nope.gml")


def test_no_building(tmp_path):
    tree = _tree()
    for member in list(tree.getroot().iter("{*}cityObjectMember")):
        member.getparent().remove(member)
    with pytest.raises(CityGmlError, match="holds no Building"):
        read_citygml(_write(tmp_path, tree))


def test_building_without_walls(tmp_path):
    tree = _tree()
    for wall in list(tree.getroot().iter("{*}WallSurface")):
        holder = wall.getparent()
        holder.getparent().remove(holder)
    with pytest.raises(CityGmlError, match="building 4018259 has no WallSurface"):
        import_citygml(_write(tmp_path, tree))


@pytest.mark.parametrize(("srs", "message"), [
    (None, "no srsName anywhere \\(building 4018259\\)"),
    ("LOCAL_CS", "building 4018259: unknown or mixed CRS \\['LOCAL_CS'\\]"),
    ("EPSG:4326", "building 4018259: CRS EPSG:4326 is in degrees"),
])
def test_missing_unknown_or_geographic_crs(tmp_path, srs, message):
    tree = _tree()
    for el in tree.getroot().iter():
        if isinstance(el.tag, str) and el.get("srsName") is not None:
            if srs is None:
                del el.attrib["srsName"]
            else:
                el.set("srsName", srs)
    with pytest.raises(CityGmlError, match=message):
        read_citygml(_write(tmp_path, tree))


def test_crs_spellings_are_understood(tmp_path):
    for srs in ("urn:ogc:def:crs:EPSG::32632", "http://www.opengis.net/def/crs/EPSG/0/32632"):
        tree = _tree()
        for el in tree.getroot().iter():
            if isinstance(el.tag, str) and el.get("srsName") is not None:
                el.set("srsName", srs)
        assert read_citygml(_write(tmp_path, tree)).crs == "EPSG:32632"


def test_ring_with_fewer_than_three_points(tmp_path):
    tree = _tree()
    polygon = _polygon(tree, "RoofSurface")
    ring_id = _set_ring(polygon, _ring(polygon)[:2])
    with pytest.raises(CityGmlError, match=f"ring {ring_id} of polygon .* has 2 point"):
        read_citygml(_write(tmp_path, tree))


def test_ring_with_a_broken_coordinate_list(tmp_path):
    tree = _tree()
    polygon = _polygon(tree, "RoofSurface")
    pos = polygon.find(".//{*}exterior//{*}posList")
    pos.text = pos.text.strip() + " 1.0"
    with pytest.raises(CityGmlError, match="not a multiple of three|in dimension 3"):
        read_citygml(_write(tmp_path, tree))


def test_degenerate_ring_is_dropped_with_a_count(tmp_path):
    tree = _tree()
    polygon = _polygon(tree, "RoofSurface")
    ring = _ring(polygon)
    _set_ring(polygon, np.stack([ring[0], ring[1], ring[0], ring[1]]))
    building = import_citygml(_write(tmp_path, tree))[0]
    warnings = building.truth.extra["warnings"]
    assert warnings["exterior ring of fewer than three distinct points (no area), polygon "
                    "dropped"] == 1


def test_self_intersecting_polygon_is_repaired_with_a_count(tmp_path):
    """Swapping two corners of a roof quad makes a bow tie: made valid (two triangles), counted,
    and the building imports."""
    tree = _tree()
    polygons = [p for p in tree.getroot().iter("{*}Polygon")
                if len(_ring(p)) in (4, 5) and p.getparent() is not None]
    polygon = next(p for p in polygons if p.xpath("ancestor::*[local-name()='RoofSurface']"))
    ring = _ring(polygon)
    ring = ring[:-1] if np.allclose(ring[0], ring[-1]) else ring
    _set_ring(polygon, np.concatenate([ring[[0, 2, 1, 3]], ring[:1]]))
    building = import_citygml(_write(tmp_path, tree))[0]
    assert building.truth.extra["warnings"]["self-intersecting polygon, made valid"] == 1
    assert building.truth.facades


def test_non_planar_polygon_is_triangulated_with_a_count(tmp_path):
    """One corner of a wall 5 cm out of its plane (tolerance 1 cm): counted, triangulated
    through its own corners, the facade areas barely move."""
    reference = import_citygml(FIXTURE)[0].truth
    tree = _tree()
    polygon = _polygon(tree, "WallSurface", 0)
    ring = _ring(polygon)
    edge = ring[1] - ring[0]
    normal = np.cross(edge, np.array([0.0, 0.0, 1.0]))
    ring[2] += 0.05 * normal / np.linalg.norm(normal)
    if np.allclose(_ring(polygon)[0], _ring(polygon)[-1]) and len(ring) == 3:
        ring[-1] = ring[0]
    _set_ring(polygon, ring)
    building = import_citygml(_write(tmp_path, tree))[0]
    assert building.truth.extra["warnings"][
        "non-planar polygon (> 1 cm), triangulated as it stands"] == 1
    assert building.truth.facade_area_m2 == pytest.approx(reference.facade_area_m2, rel=0.02)


def test_inside_out_file_is_flipped_with_a_warning(tmp_path):
    """Every ring reversed (an exporter writing clockwise rings): the enclosed volume is
    negative, all surfaces are flipped back, and the truth is the same."""
    reference = import_citygml(FIXTURE)[0].truth
    tree = _tree()
    for pos in tree.getroot().iter("{*}posList"):
        pts = np.asarray(pos.text.split(), dtype=float).reshape(-1, 3)[::-1]
        pos.text = " ".join(repr(float(x)) for x in pts.reshape(-1))
    building = import_citygml(_write(tmp_path, tree))[0]
    assert building.truth.extra["warnings"][
        "surfaces faced inwards (negative enclosed volume): all flipped"] == 1
    assert building.truth.window_area_m2 == pytest.approx(reference.window_area_m2, rel=1e-9)
    assert building.truth.facade_area_m2 == pytest.approx(reference.facade_area_m2, rel=1e-9)
    np.testing.assert_allclose([f.normal for f in building.truth.facades],
                               [f.normal for f in reference.facades], atol=1e-5)


def test_xlink_to_nothing(tmp_path):
    tree = _tree()
    member = next(tree.getroot().iter("{*}surfaceMember"))
    for child in list(member):
        member.remove(child)
    member.set("{http://www.w3.org/1999/xlink}href", "#no_such_polygon")
    with pytest.raises(CityGmlError, match="building 4018259: xlink:href '#no_such_polygon' "
                                           "points to no element"):
        read_citygml(_write(tmp_path, tree))
