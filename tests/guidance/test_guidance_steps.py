"""The named steps of procedure guidance alone (no JSBSim): leg-end conditions, the DF-passed
rule of re-planning, the arc speed cap of the speed plan."""

from __future__ import annotations

import math

import pytest

from fms_testbed.core.geodesy import direct
from fms_testbed.core.segments import Arc, Line
from fms_testbed.core.units import G0_MPS2, NM_M
from fms_testbed.guidance.geometry import local_pieces
from fms_testbed.guidance.sequencing import ConditionWatch, direct_fix_passed
from fms_testbed.guidance.speed_plan import ARC_BANK_MARGIN_DEG, arc_speed_cap_mps
from fms_testbed.legs.model import BuiltLeg, FlightState, Termination

NAV = (47.0, -122.0)


def _rad(lat_lon):
    return math.radians(lat_lon[0]), math.radians(lat_lon[1])


def _at(az, dist_m, frm=NAV):
    return direct(frm[0], frm[1], az, dist_m)[:2]


def test_dme_condition_is_met_once_the_distance_is_crossed():
    t = Termination("dme", dme_m=12 * NM_M, navaid_lat_deg=NAV[0], navaid_lon_deg=NAV[1])
    w = ConditionWatch()
    ranges_nm = [10.0, 11.0, 11.9, 12.1]
    met = [w.met(t, *_rad(_at(90.0, r * NM_M)), 1000.0) for r in ranges_nm]
    assert met == [False, False, False, True]
    w.reset()   # a new leg: the first check only records the side
    assert not w.met(t, *_rad(_at(90.0, 13 * NM_M)), 1000.0)


def test_radial_condition_is_met_once_the_radial_is_crossed():
    t = Termination("radial", radial_deg=45.0, navaid_lat_deg=NAV[0], navaid_lon_deg=NAV[1])
    w = ConditionWatch()
    met = [w.met(t, *_rad(_at(brg, 8 * NM_M)), 1000.0) for brg in (20.0, 40.0, 44.0, 46.0)]
    assert met == [False, False, False, True]


def test_altitude_condition():
    t = Termination("altitude", alt_m=900.0)
    w = ConditionWatch()
    assert not w.met(t, *_rad(NAV), 899.0) and w.met(t, *_rad(NAV), 900.0)


def _df(fix):
    st = FlightState(*NAV, 0.0, 0.0)
    return BuiltLeg(0, None, "DF", st, st, Termination("fix", *fix, fix_ident="X"), 120.0)


def test_a_df_fix_behind_within_a_turn_diameter_counts_as_passed():
    v = 120.0
    r = v * v / (G0_MPS2 * math.tan(math.radians(20.0)))
    trk = math.radians(0.0)
    assert direct_fix_passed(_df(_at(180.0, 1.5 * r)), *_rad(NAV), trk, v)      # behind
    assert not direct_fix_passed(_df(_at(180.0, 2.5 * r)), *_rad(NAV), trk, v)  # far behind
    assert not direct_fix_passed(_df(_at(0.0, 1.5 * r)), *_rad(NAV), trk, v)    # ahead
    assert direct_fix_passed(_df(_at(0.0, 0.2 * NM_M)), *_rad(NAV), trk, v)     # overhead
    tf = _df(_at(180.0, 1.5 * r))
    assert not direct_fix_passed(BuiltLeg(0, None, "TF", tf.start, tf.end, tf.termination,
                                          120.0), *_rad(NAV), trk, v)


def test_arc_speed_cap_applies_within_the_deceleration_distance():
    """v_cap = sqrt(R g tan(γ_max − margin)) for an arc close enough ahead, none beyond."""
    bank_max = 25.0
    r_arc = 3000.0
    a_end = _at(0.0, 5000.0)
    pieces = local_pieces([Line(*NAV, *a_end),
                           Arc(*_at(90.0, r_arc, a_end), r_arc, 270.0, 90.0)])
    cap = math.sqrt(r_arc * G0_MPS2 * math.tan(math.radians(bank_max - ARC_BANK_MARGIN_DEG)))
    assert arc_speed_cap_mps(pieces, 0, 0.0, 200.0, bank_max) == pytest.approx(cap, rel=1e-6)
    assert arc_speed_cap_mps(pieces, 0, 0.0, 50.0, bank_max) == math.inf  # slow, arc 5 km away
