"""The OpenDRIVE reader: reference-line geometry against closed forms and numerical
integrals, lane centres, the header's frame, and the real Ingolstadt road in both of the
source's frames (tests/fixtures/opendrive, CC BY-NC-SA 4.0)."""

from __future__ import annotations

import numpy as np
import pytest
from paths import FIXTURES
from scipy.integrate import quad

from dataset.importers.opendrive.read import (
    Geometry,
    OpenDriveError,
    geometry_xy,
    lane_lines,
    read_opendrive,
    reference_points,
    spiral_xy,
)
from dataset.importers.opendrive.streets import streets_in_frame

ROAD = FIXTURES / "opendrive" / "ingolstadt_road_1444000.xodr.xz"
ROAD_OFFSET = FIXTURES / "opendrive" / "ingolstadt_road_1444000_offset.xodr.xz"


def _xodr(tmp_path, planview: str, lanes: str = "", header: str = "") -> str:
    text = f"""<?xml version="1.0"?>
<OpenDRIVE><header revMajor="1" revMinor="4">{header}</header>
<road id="7" junction="-1" length="10"><planView>{planview}</planView>
<elevationProfile><elevation s="0" a="2" b="0.1" c="0" d="0"/></elevationProfile>
<lanes>{lanes}</lanes></road></OpenDRIVE>"""
    path = tmp_path / "road.xodr"
    path.write_text(text)
    read_opendrive.cache_clear()
    return read_opendrive(path)


def test_arc_quarter_circle_closed_form():
    r = 8.0
    g = Geometry(0.0, 3.0, -1.0, np.pi / 2, np.pi * r / 2, "arc", (("curvature", 1 / r),))
    xy, hdg = geometry_xy(g, np.array([0.0, np.pi * r / 2]))
    # heading north, turning left by 90 degrees around (3 - r, -1): ends at (3 - r, -1 + r)
    np.testing.assert_allclose(xy, [[3.0, -1.0], [3.0 - r, -1.0 + r]], atol=1e-12)
    np.testing.assert_allclose(hdg, [np.pi / 2, np.pi], atol=1e-12)


@pytest.mark.parametrize(("k0", "rate"), [(0.0, 0.01), (0.05, -0.012), (-0.1, 0.004)])
def test_spiral_matches_numerical_integral(k0, rate):
    def heading(u: float) -> float:
        return k0 * u + 0.5 * rate * u * u

    s = np.array([0.0, 3.7, 12.5, 25.0])
    xy, turn = spiral_xy(k0, rate, s)
    for si, p, t in zip(s, xy, turn):
        x = quad(lambda u: np.cos(heading(u)), 0.0, si, epsabs=1e-13)[0]
        y = quad(lambda u: np.sin(heading(u)), 0.0, si, epsabs=1e-13)[0]
        np.testing.assert_allclose(p, [x, y], atol=1e-9)
        assert t == pytest.approx(heading(si), abs=1e-12)


def test_poly3_lies_on_its_cubic_with_its_length():
    a, b, c, d = 0.5, 0.1, 0.02, -0.001
    u = np.linspace(0, 20, 200001)
    arc = np.concatenate([[0], np.cumsum(np.hypot(np.diff(u), np.diff(a + b*u + c*u**2
                                                                        + d*u**3)))])
    length = float(arc[-1])
    g = Geometry(0.0, 0.0, 0.0, 0.0, length, "poly3", (("a", a), ("b", b), ("c", c), ("d", d)))
    xy, hdg = geometry_xy(g, np.linspace(0, length, 9))
    np.testing.assert_allclose(xy[:, 1], a + b * xy[:, 0] + c * xy[:, 0]**2 + d * xy[:, 0]**3,
                               atol=1e-12)
    assert xy[-1, 0] == pytest.approx(20.0, abs=1e-3)  # the length reaches u = 20
    np.testing.assert_allclose(np.tan(hdg), b + 2 * c * xy[:, 0] + 3 * d * xy[:, 0]**2,
                               atol=1e-12)


def test_lane_centres_and_header_offset(tmp_path):
    lanes = """<laneOffset s="0" a="1" b="0" c="0" d="0"/><laneSection s="0">
      <left><lane id="1" type="driving"><width sOffset="0" a="3" b="0" c="0" d="0"/></lane>
      </left><center><lane id="0" type="none"/></center>
      <right><lane id="-1" type="sidewalk"><width sOffset="0" a="3" b="0" c="0" d="0"/></lane>
      <lane id="-2" type="driving"><width sOffset="0" a="3.5" b="0" c="0" d="0"/></lane>
      </right></laneSection>"""
    line = '<geometry s="0" x="0" y="0" hdg="0" length="10"><line/></geometry>'
    net = _xodr(tmp_path, line, lanes)
    by_id = {lane.lane_id: lane.points_m for lane in lane_lines(net)}
    assert set(by_id) == {1, -2}
    np.testing.assert_allclose(by_id[1][:, 1], 1 + 1.5)  # offset + half its width, left
    np.testing.assert_allclose(by_id[-2][:, 1], 1 - 3 - 1.75)  # past the sidewalk, right
    np.testing.assert_allclose(by_id[-2][[0, -1], 0], [0, 10])
    np.testing.assert_allclose(by_id[-2][:, 2], 2 + 0.1 * by_id[-2][:, 0])  # elevation
    assert np.diff(by_id[-2][:, 0]).max() <= 0.5 + 1e-12
    moved = _xodr(tmp_path, line, lanes, '<offset x="100" y="50" z="-3" hdg="1.5707963267948966"/>')
    pts = {lane.lane_id: lane.points_m for lane in lane_lines(moved)}[1]
    # rotated by 90 degrees, then shifted: (s, 2.5) -> (100 - 2.5, 50 + s)
    np.testing.assert_allclose(pts[:, :2], np.column_stack([100 - 2.5 + 0 * pts[:, 0],
                                                             50 + by_id[1][:, 0]]), atol=1e-9)
    np.testing.assert_allclose(pts[:, 2], by_id[1][:, 2] - 3)


def test_bad_input_is_named(tmp_path):
    with pytest.raises(OpenDriveError, match="bezier"):
        _xodr(tmp_path, '<geometry s="0" x="0" y="0" hdg="0" length="1"><bezier/></geometry>')
    bad = tmp_path / "x.xodr"
    bad.write_text("<CityModel/>")
    with pytest.raises(OpenDriveError, match="not OpenDRIVE"):
        read_opendrive(bad)
    net = _xodr(tmp_path, '<geometry s="0" x="0" y="0" hdg="0" length="10"><line/></geometry>')
    with pytest.raises(OpenDriveError, match="geoReference"):
        streets_in_frame(net.path, "EPSG:32632", (0.0, 0.0, 0.0))


def test_real_road_records_join_and_both_frames_agree():
    """The source's paramPoly3 records of road 1444000 end where the next begins (its
    numbers: 1 micrometre), and its file in the shifted PROJ frame maps onto the UTM one."""
    read_opendrive.cache_clear()
    net = read_opendrive(ROAD)
    (road,) = net.roads
    assert [g.kind for g in road.geometry] == ["paramPoly3"] * 10
    for g, h in zip(road.geometry[:-1], road.geometry[1:]):
        end, hdg = geometry_xy(g, np.array([g.length_m]))
        assert np.hypot(end[0, 0] - h.x_m, end[0, 1] - h.y_m) < 1e-3
        assert abs(np.angle(np.exp(1j * (hdg[0] - h.hdg_rad)))) < 1e-2
    xy, _ = reference_points(road, np.array([0.0, road.length_m]))
    assert np.hypot(*(xy[1] - xy[0])) < road.length_m  # a bent road
    offset = (-678000.0, -5403600.0, -414.0)
    utm = streets_in_frame(ROAD, "EPSG:32632", offset)
    shifted = streets_in_frame(ROAD_OFFSET, "EPSG:32632", offset)
    assert [s.name for s in utm] == [s.name for s in shifted] and len(utm) >= 15
    for a, b in zip(utm, shifted):
        np.testing.assert_allclose(a.points_m, b.points_m, atol=1e-3)
    near = np.concatenate([s.points_m for s in utm])
    assert np.abs(near[:, :2]).max() < 200 and np.abs(near[:, 2]).max() < 3  # in the frame
