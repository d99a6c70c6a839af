"""Air-data computer: a perfect one reports the truth; errors move the outputs as the
air-data equations say."""

from __future__ import annotations

import dataclasses

import pytest

from fms_testbed.config.aircraft import load_aircraft
from fms_testbed.core.atmosphere import isa
from fms_testbed.sensors.air_data import AirDataComputer, AirDataSpec
from fms_testbed.sim.jsbsim_core import JSBSimAircraft


@pytest.fixture(scope="module")
def truth():
    ac = JSBSimAircraft(load_aircraft("737"))
    ac.trim(3000.0, 400 / 3.6, heading_deg=90.0, lat_deg=47.0, lon_deg=8.0)
    return ac.state()


def test_perfect_computer_reports_truth_and_the_pressure_altitude_of_jsbsim_air(truth):
    a = AirDataComputer().update(truth)
    assert (a.tas_mps, a.cas_mps, a.mach) == (truth.tas_mps, truth.cas_mps, truth.mach)
    _, p_isa, _ = isa(3000.0)
    # JSBSim's static pressure at 3,000 m geometric (2,998.6 m geopotential) on a standard day
    assert truth.p_static_pa == pytest.approx(float(p_isa), rel=3e-4)
    assert a.pressure_alt_m == pytest.approx(3000.0, abs=3.0)
    assert a.baro_alt_m == truth.alt_m


def test_errors_enter_through_the_air_data_equations(truth):
    a0 = AirDataComputer().update(truth)
    a = AirDataComputer(AirDataSpec(tas_scale=0.01)).update(truth)
    assert a.mach == pytest.approx(1.01 * truth.mach, rel=1e-12)
    # T_s = T_t / (1 + 0.2 M²) from the higher M: TAS a little less than 1 % high
    m2 = truth.mach ** 2
    ratio = 1.01 * ((1 + 0.2 * m2) / (1 + 0.2 * 1.01 ** 2 * m2)) ** 0.5
    assert a.tas_mps / a0.tas_mps == pytest.approx(ratio, rel=1e-3)
    assert a.tas_mps / a0.tas_mps < 1.01 - 1e-4
    # a static source reading 100 Pa high shows a lower altitude: dh = -R T / (g p) dp
    b = AirDataComputer(AirDataSpec(static_pressure_bias_pa=100.0)).update(truth)
    dh = -287.05287 * truth.t_static_k / (9.80665 * truth.p_static_pa) * 100.0
    assert b.pressure_alt_m - a0.pressure_alt_m == pytest.approx(dh, rel=0.01)
    assert b.baro_alt_m - truth.alt_m == pytest.approx(b.pressure_alt_m - a0.pressure_alt_m)
    assert dataclasses.replace(AirDataSpec()) == AirDataSpec()
