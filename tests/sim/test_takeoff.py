"""JSBSim on the ground (sim/takeoff.py): the ground start of each shipped aircraft, and the
direct controls of the takeoff roll (throttle, nose-wheel steering) act as documented."""

from __future__ import annotations

import math

import pytest

from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.core.geodesy import inverse
from fms_testbed.core.units import FT_M
from fms_testbed.sim.jsbsim_core import JSBSimAircraft
from fms_testbed.sim.takeoff import ground_start, handover, set_controls

LAT, LON, ELEV_M, HDG = 47.46, -122.31, 130.0, 340.0


def _on_ground(name: str) -> JSBSimAircraft:
    cfg = load_aircraft(name)
    ac = JSBSimAircraft(cfg)
    ground_start(ac, LAT, LON, ELEV_M, HDG, cfg.takeoff.flaps_norm)
    return ac


@pytest.mark.parametrize("name", ["737", "c172p", "global5000"])
def test_ground_start_rests_on_the_gear_at_the_runway_point(name):
    ac = _on_ground(name)
    f = ac.fdm
    s = ac.state()
    assert f["gear/wow"] > 0.5 and f["gear/gear-pos-norm"] == pytest.approx(1.0)
    # CG above the runway by the gear height (measured 1.1-2.7 m), terrain at the runway
    assert f["position/terrain-elevation-asl-ft"] * FT_M == pytest.approx(ELEV_M, abs=0.01)
    assert 0.5 < s.agl_m < 4.0
    assert abs(math.degrees(s.pitch_rad)) < 5.0 and abs(math.degrees(s.roll_rad)) < 1.0
    d, _, _ = inverse(LAT, LON, math.degrees(s.lat_rad), math.degrees(s.lon_rad))
    assert d < 1.0
    assert math.degrees(s.heading_rad) % 360.0 == pytest.approx(HDG, abs=0.5)
    assert ac.trim_result is not None and ac.trim_result.tas_mps == 0.0
    # flaps at the takeoff setting and held there
    ac.run(240)
    assert f["fcs/flap-pos-norm"] == pytest.approx(ac.cfg.takeoff.flaps_norm, abs=0.01)
    assert f["gear/wow"] > 0.5 and ac.state().agl_m > 0.5


def test_throttle_and_nose_wheel_steer_the_737_on_the_ground():
    ac = _on_ground("737")
    set_controls(ac, throttle=0.6)
    ac.run(int(15 / ac.dt_s))
    s = ac.state()
    assert s.gs_mps > 5.0                                     # it rolls under thrust
    assert abs(math.degrees(s.heading_rad) % 360.0 - HDG) < 0.5   # straight with no steering
    set_controls(ac, steer=0.3)                               # positive: nose right
    ac.run(int(5 / ac.dt_s))
    turned = (math.degrees(ac.state().heading_rad) - HDG + 180.0) % 360.0 - 180.0
    assert turned > 2.0
    handover(ac)                       # loops engaged about the surfaces of the moment
    assert ac.fdm["fcs/steer-cmd-norm"] == 0.0 and ac.fdm["fms/ap/bank-engage"] == 1.0
