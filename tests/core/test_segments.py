"""Path segments (Line/Arc) and projection on WGS-84: exact cases and hypothesis properties."""

import math

import pytest
from geographiclib.geodesic import Geodesic
from hypothesis import given, settings
from hypothesis import strategies as st

from fms_testbed.core.segments import Arc, Line, project, turn_angle_deg
from fms_testbed.core.geodesy import direct, inverse

G = Geodesic.WGS84


def test_line_length_and_courses_match_geographiclib():
    ln = Line(50.0, 10.0, 50.5, 11.0)
    r = G.Inverse(50.0, 10.0, 50.5, 11.0)
    assert ln.length_m() == pytest.approx(r["s12"], abs=1e-6)
    assert ln.start_course_deg == pytest.approx(r["azi1"] % 360, abs=1e-9)
    assert ln.end_course_deg == pytest.approx(r["azi2"] % 360, abs=1e-9)
    lat, lon = ln.point_at(ln.length_m())
    assert inverse(lat, lon, 50.5, 11.0)[0] < 1e-6


def test_arc_length_endpoints_and_courses():
    arc = Arc(40.0, -100.0, 3000.0, 270.0, 90.0)  # right turn, starting west of the centre
    assert arc.length_m() == pytest.approx(3000.0 * math.pi / 2)
    assert arc.turn == "R"
    for p in (arc.start, arc.end, arc.point_at(1234.0)):
        assert inverse(40.0, -100.0, *p)[0] == pytest.approx(3000.0, abs=1e-6)
    # west of the centre, turning right: north, up to the meridian convergence over 3 km
    assert abs((arc.start_course_deg + 180) % 360 - 180) < 0.05
    assert arc.end_course_deg == pytest.approx(90.0, abs=0.05)
    # the tangent is exactly perpendicular to the radial geodesic at the point
    _, _, radial_at_start = inverse(40.0, -100.0, *arc.start)
    assert (arc.start_course_deg - radial_at_start) % 360 == pytest.approx(90.0, abs=1e-9)
    left = Arc(40.0, -100.0, 3000.0, 90.0, -90.0)
    assert left.turn == "L" and abs((left.start_course_deg + 180) % 360 - 180) < 0.05


def test_project_line_right_of_path_is_positive_xtk():
    ln = Line(0.0, 0.0, 0.0, 1.0)  # eastbound along the equator
    lat, lon, _ = direct(0.0, 0.5, 180.0, 200.0)  # 200 m south = right of an eastbound path
    along, xtk, trk, curv = project(ln, lat, lon)
    assert xtk == pytest.approx(200.0, abs=0.01)
    assert along == pytest.approx(ln.length_m() / 2, abs=0.01)
    assert math.degrees(trk) == pytest.approx(90.0, abs=1e-6)
    assert curv == 0.0


def test_project_arc_signs_for_right_and_left_turns():
    right = Arc(45.0, 5.0, 2000.0, 270.0, 180.0)
    inside = direct(45.0, 5.0, 0.0, 1500.0)[:2]   # inside a right turn = right of path
    along, xtk, trk, curv = project(right, *inside)
    assert xtk == pytest.approx(500.0, abs=1e-6)
    assert along == pytest.approx(2000.0 * math.pi / 2, rel=1e-9)
    assert math.degrees(trk) == pytest.approx(90.0, abs=1e-6)
    assert curv == pytest.approx(1 / 2000.0)
    left = Arc(45.0, 5.0, 2000.0, 90.0, -180.0)
    along, xtk, trk, curv = project(left, *inside)
    assert xtk == pytest.approx(-500.0, abs=1e-6) and curv < 0


def test_turn_angle_respects_coded_direction_above_180():
    assert turn_angle_deg(0.0, 90.0) == pytest.approx(90.0)
    assert turn_angle_deg(0.0, 90.0, "L") == pytest.approx(-270.0)
    assert turn_angle_deg(350.0, 10.0, "R") == pytest.approx(20.0)
    assert turn_angle_deg(10.0, 350.0, "R") == pytest.approx(340.0)


def test_arc_rejects_non_positive_radius():
    with pytest.raises(ValueError):
        Arc(0.0, 0.0, 0.0, 0.0, 90.0)


@settings(max_examples=60, deadline=None)
@given(lat=st.floats(-70, 70), lon=st.floats(-179, 179), crs=st.floats(0, 360),
       length=st.floats(200.0, 200_000.0), frac=st.floats(0.0, 1.0),
       off=st.floats(-5000.0, 5000.0))
def test_project_line_recovers_along_and_cross_track(lat, lon, crs, length, frac, off):
    """A point put at (along, offset) by a perpendicular geodesic projects back to it."""
    lat2, lon2, _ = direct(lat, lon, crs, length)
    ln = Line(lat, lon, lat2, lon2)
    s = frac * ln.length_m()
    flat, flon = ln.point_at(s)
    c = ln.course_at(s)
    plat, plon, _ = direct(flat, flon, c + 90.0, off)
    along, xtk, trk, _ = project(ln, plat, plon)
    assert along == pytest.approx(s, abs=0.05)
    assert xtk == pytest.approx(off, abs=0.05)


@settings(max_examples=60, deadline=None)
@given(lat=st.floats(-70, 70), lon=st.floats(-179, 179), r=st.floats(300.0, 30_000.0),
       r0=st.floats(0, 360), sweep=st.floats(-359.0, 359.0).filter(lambda x: abs(x) > 1.0),
       frac=st.floats(0.0, 1.0), dr=st.floats(-200.0, 200.0))
def test_project_arc_recovers_along_and_cross_track(lat, lon, r, r0, sweep, frac, dr):
    arc = Arc(lat, lon, r, r0, sweep)
    s = frac * arc.length_m()
    radial = arc.radial_at(s)
    plat, plon, _ = direct(lat, lon, radial, r + dr)
    along, xtk, trk, curv = project(arc, plat, plon)
    assert along == pytest.approx(s, abs=1e-3 * r + 1e-6)
    expected = -dr if sweep > 0 else dr     # outside a right turn is left of the path
    assert xtk == pytest.approx(expected, abs=1e-6)
    # desired track: the course at the foot point, up to the meridian convergence over
    # |dr| <= 200 m (below 0.005 deg up to 70 deg latitude)
    assert abs(((math.degrees(trk) - arc.course_at(s)) + 180) % 360 - 180) < 0.006
