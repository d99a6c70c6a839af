"""Measured vs planned conditions (guidance/conditions): the air-velocity vector, the filtered
wind and temperature from the air data and the navigation solution, the rebuild reason and the
build settings for the measured conditions."""

from __future__ import annotations

import math
import numpy as np
import pytest

from fms_testbed.core.atmosphere import GAMMA, R_JPKGK, isa
from fms_testbed.core.units import KT_MPS
from fms_testbed.core.wind import WindProfile
from fms_testbed.core.state import AirData, NavSolution
from fms_testbed.guidance.conditions import (ConditionMonitor, ConditionThresholds,
                                             air_velocity_ned_mps, measured_params)
from fms_testbed.legs.model import BuildParams


def test_air_velocity_in_a_banked_turn_has_the_alpha_part_sideways():
    """Level, heading north, α 4°, bank 25° right, pitch = α: the body-z part of the air
    velocity points to the right of the heading in the turn."""
    a = math.radians(4.0)
    n, e, d = air_velocity_ned_mps(100.0, a, 0.0, math.radians(25.0), a, 0.0)
    assert math.hypot(n, e) == pytest.approx(100.0 * math.cos(0.0), rel=2e-3)
    assert e < -1.0 or e > 1.0          # 1.7° of track off the heading, not zero
    n0, e0, d0 = air_velocity_ned_mps(100.0, a, 0.0, 0.0, a, 0.0)
    assert e0 == pytest.approx(0.0, abs=1e-9) and d0 == pytest.approx(0.0, abs=1e-9)
    assert n0 == pytest.approx(100.0)


def _sample(t_s, wind_ne, dev, alt_m=3000.0, tas=130.0, hdg=math.radians(60.0)):
    t = float(isa(alt_m, dev)[0])
    mach = tas / math.sqrt(GAMMA * R_JPKGK * t)
    an, ae = tas * math.cos(hdg), tas * math.sin(hdg)
    nav = NavSolution(t_s, 0.8, 0.1, alt_m, np.array([ae + wind_ne[1], an + wind_ne[0], 0.0]),
                      0.0, 0.0, hdg)
    air = AirData(t_s, tas, tas, mach, alt_m, alt_m, 0.0, 70000.0, t, 0.0, 0.0)
    return nav, air


def test_monitor_triggers_on_wind_and_on_temperature_after_the_holdoff():
    planned = BuildParams(wind_speed_mps=20 * KT_MPS, wind_from_deg=270.0, isa_dev_c=0.0)
    wn, we = WindProfile.constant(20 * KT_MPS, 270.0).ned_at(0.0)
    m = ConditionMonitor(ConditionThresholds())
    for k in range(300):       # as planned: never
        assert m.update(0.1 * k, *_sample(0.1 * k, (wn, we), 0.0), planned) == ""
    # the wind backs to 230 at 40 kt (vector error ~27 kt) and the day is 8 °C warm
    w2 = WindProfile.constant(40 * KT_MPS, 230.0).ned_at(0.0)
    why = ""
    for k in range(300, 1200):
        why = m.update(0.1 * k, *_sample(0.1 * k, w2, 8.0), planned)
        if why:
            break
    assert "wind measured 2" in why and "vs planned 270/20 kt" in why and "vector error" in why
    assert "temperature measured ISA+" in why
    (mn, me), dev = m.measured
    assert math.hypot(mn - w2[0], me - w2[1]) < 10 * KT_MPS and dev > 5.0
    m.rebuilt(0.1 * k)
    assert m.update(0.1 * k + 1.0, *_sample(0.1 * k + 1, w2, 8.0), planned) == ""   # held off


def test_no_valid_air_data_no_measurement():
    m = ConditionMonitor()
    nav, air = _sample(100.0, (0.0, 0.0), 0.0)
    air.valid = False
    assert m.update(100.0, nav, air, BuildParams()) == ""
    assert m.measured == ((None, None), None)


def test_measured_params_shift_the_planned_profile():
    prof = WindProfile.from_layers([(0.0, 270.0, 10.0), (3000.0, 270.0, 30.0)])
    p = BuildParams(wind_profile=prof, wind_speed_mps=10.0, wind_from_deg=270.0)
    meas = WindProfile.constant(25.0, 270.0).ned_at(0.0)     # 5 m/s more than planned at 1500
    q = measured_params(p, 1500.0, meas, 12.0)
    assert q.isa_dev_c == 12.0
    assert q.wind_at(1500.0)[0] == pytest.approx(25.0)
    assert q.wind_at(3000.0)[0] == pytest.approx(35.0)      # the profile's shape kept
    c = measured_params(BuildParams(), 0.0, meas, 0.0)       # no profile: the measured wind
    assert c.wind_profile is None and c.wind_at(9000.0) == pytest.approx((25.0, 270.0))


def test_a_heading_error_the_navigation_declares_is_not_taken_for_a_wind_change():
    """An INS/GNSS solution whose heading is 2.6° off with σ 2.8° (not yet observable before a
    turn) makes a still air look like a 12 kt crosswind at 130 m/s: no rebuild while that is
    within 3 σ of the heading's own wind error; the same error with the σ not declared (or a
    heading known to 0.1°) does trigger — and so does a real wind change beyond the 3 σ."""
    planned = BuildParams(wind_speed_mps=0.0, wind_from_deg=0.0, isa_dev_c=0.0)

    def run(sigma_rad, true_wind=(0.0, 0.0)):
        m = ConditionMonitor(ConditionThresholds())
        for k in range(1500):
            nav, air = _sample(0.1 * k, true_wind, 0.0)
            nav.heading_rad += math.radians(2.6)        # the navigation's heading error
            nav.heading_sigma_rad = sigma_rad
            why = m.update(0.1 * k, nav, air, planned)
            if why:
                return why
        return ""

    assert run(math.radians(2.8)) == ""
    assert "wind measured" in run(None)
    assert "wind measured" in run(math.radians(0.1))
    w = WindProfile.constant(45 * KT_MPS, 150.0).ned_at(0.0)   # beyond 3 × 130 m/s × 2.8°
    assert "wind measured" in run(math.radians(2.8), w)
