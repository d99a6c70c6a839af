"""The coded paths the path definition error is measured from (legs/coded.py): distances of
points placed with the direct geodesic problem at known offsets."""

from __future__ import annotations

import math

import pytest

from fms_testbed.core.geodesy import direct
from fms_testbed.core.units import NM_M
from fms_testbed.legs.coded import (CodedCircle, course_from, course_into,
                                    path_definition_error_m, racetrack, track_between)

FIX = (47.5, -122.3)


def _at(az_deg, dist_m, frm=FIX):
    lat, lon, _ = direct(frm[0], frm[1], az_deg, dist_m)
    return lat, lon


def test_course_line_distance_is_the_offset_from_the_geodesic_even_beyond_its_ends():
    crs = 250.0
    into, out = course_into(*FIX, crs), course_from(*FIX, crs)
    for along_m in (-30 * NM_M, -2000.0, 0.0, 3000.0, 25 * NM_M):  # behind, at, past the fix
        foot = _at(crs, along_m) if along_m >= 0 else _at(crs + 180.0, -along_m)
        for off_m in (0.0, 150.0, 2500.0):
            p = _at(crs + 90.0, off_m, foot)
            assert into.distance_m(*p) == pytest.approx(off_m, abs=0.05 + 2e-4 * off_m)
            assert out.distance_m(*p) == pytest.approx(off_m, abs=0.05 + 2e-4 * off_m)


def test_track_between_coincident_fixes_is_undefined():
    assert track_between(*FIX, *FIX) is None
    assert track_between(*FIX, *_at(10.0, 5000.0)) is not None


def test_circle_distance_is_the_radius_difference():
    c = CodedCircle(*FIX, 3.0 * NM_M)
    assert c.distance_m(*_at(123.0, 3.0 * NM_M)) == pytest.approx(0.0, abs=1e-6)
    assert c.distance_m(*_at(300.0, 3.0 * NM_M + 40.0)) == pytest.approx(40.0, abs=1e-6)
    assert c.distance_m(*_at(10.0, 1.0 * NM_M)) == pytest.approx(2.0 * NM_M, abs=1e-6)


@pytest.mark.parametrize("inbound", [0.0, 180.0])
@pytest.mark.parametrize("turn, side", [("R", 1.0), ("L", -1.0)])
def test_racetrack_distance_on_its_legs_turns_and_off_it(turn, side, inbound):
    """At the equator on a meridian inbound course the points below are placed exactly with
    constant azimuths (no meridian convergence there)."""
    fix = (0.0, 10.0)
    leg_m, r_m = 4 * NM_M, 3500.0
    rt = racetrack(*fix, inbound, turn, leg_m, r_m)
    back = inbound + 180.0
    abeam = inbound + 90.0 * side    # toward the holding side

    def pt(behind_m, lateral_m):     # behind the fix along the inbound, toward the hold side
        base = _at(back, behind_m, fix) if behind_m >= 0 else _at(inbound, -behind_m, fix)
        return _at(abeam, lateral_m, base) if lateral_m >= 0 else \
            _at(abeam + 180.0, -lateral_m, base)

    tol = 0.05
    assert rt.distance_m(*fix) == pytest.approx(0.0, abs=tol)                   # the fix
    assert rt.distance_m(*pt(0.5 * leg_m, 0.0)) == pytest.approx(0.0, abs=tol)  # inbound leg
    assert rt.distance_m(*pt(0.5 * leg_m, 2 * r_m)) == pytest.approx(0.0, abs=tol)  # outbound
    assert rt.distance_m(*pt(-r_m, r_m)) == pytest.approx(0.0, abs=tol)   # outbound turn apex
    assert rt.distance_m(*pt(leg_m + r_m, r_m)) == pytest.approx(0.0, abs=tol)  # inbound turn
    assert rt.distance_m(*pt(0.5 * leg_m, r_m)) == pytest.approx(r_m, abs=tol)  # the middle
    assert rt.distance_m(*pt(0.5 * leg_m, -300.0)) == pytest.approx(300.0, abs=tol)  # outside
    assert rt.distance_m(*pt(-r_m - 200.0, r_m)) == pytest.approx(200.0, abs=tol)  # beyond apex
    # the non-holding side is not the pattern: the mirror of the outbound leg is 2R from it
    assert rt.distance_m(*pt(0.5 * leg_m, -2 * r_m)) == pytest.approx(2 * r_m, abs=tol)


def test_pde_is_the_largest_distance_of_the_points():
    c = CodedCircle(*FIX, 1000.0)
    pts = [_at(0.0, 1000.0), _at(90.0, 1010.0), _at(180.0, 975.0)]
    assert path_definition_error_m(c, pts) == pytest.approx(25.0, abs=1e-6)
    assert math.isfinite(path_definition_error_m(c, pts))
