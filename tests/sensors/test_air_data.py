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


def test_typical_errors_have_the_declared_altitude_and_airspeed_spread(truth):
    """Over 400 installations: the pressure-altitude error's σ is what the static-source
    residual and the transducer bias give through dh = -R T / (g p) dp, the Mach error's σ is
    the q_c and Mach-scale errors' (first order), the vanes' biases their σ."""
    import math

    import numpy as np

    from fms_testbed.core.units import G0_MPS2
    from fms_testbed.sensors.air_data import TYPICAL

    sp = TYPICAL.spec
    m2 = truth.mach ** 2
    qc = truth.p_static_pa * ((1 + 0.2 * m2) ** 3.5 - 1)
    dp = math.hypot(qc * math.hypot(sp.static_position_error,
                                    sp.static_position_error_per_rad * truth.alpha_rad),
                    sp.static_pressure_bias_pa)
    want_h = 287.05287 * truth.t_static_k / (G0_MPS2 * truth.p_static_pa) * dp
    dh, dm, da = [], [], []
    a0 = AirDataComputer().update(truth)
    for seed in range(400):
        a = AirDataComputer.from_spec({"errors": "typical"}, seed).update(truth)
        dh.append(a.pressure_alt_m - a0.pressure_alt_m)
        dm.append(a.mach / truth.mach - 1)
        da.append(a.alpha_rad - truth.alpha_rad)
    assert np.std(dh) == pytest.approx(want_h, rel=0.15)
    assert np.std(da) == pytest.approx(math.hypot(sp.alpha_bias_rad, sp.vane_noise_rad,
                                                  sp.alpha_scale * truth.alpha_rad), rel=0.15)
    assert 0.001 < np.std(dm) < 0.01


def test_lags_and_the_scenario_key(truth):
    import math

    from fms_testbed.config.scenario import parse_scenario
    from fms_testbed.core.errors import ConfigError

    spec = AirDataSpec(static_pressure_bias_pa=0.0, static_lag_s=2.0, temperature_lag_s=1.0,
                       tas_scale=1e-12)
    adc = AirDataComputer(spec)
    adc.update(truth)
    step = dataclasses.replace(truth, p_static_pa=truth.p_static_pa + 200.0,
                               t_s=truth.t_s + 2.0)
    a = adc.update(step)
    assert a.p_static_pa - truth.p_static_pa == pytest.approx(200 * (1 - math.exp(-1)), rel=1e-9)
    assert AirDataComputer.from_spec(None).update(truth).tas_mps == truth.tas_mps
    assert AirDataComputer.from_spec({"errors": "none"}).update(truth).mach == truth.mach
    with pytest.raises(ConfigError, match="air_data.errors"):
        AirDataComputer.from_spec({"errors": "bad"})
    with pytest.raises(ConfigError, match="air_data.sigma"):
        AirDataComputer.from_spec({"sigma": 1})
    base = {"aircraft": "737", "initial": {"alt_m": 3000, "tas_kmh": 400}, "duration_s": 10}
    assert parse_scenario(base).air_data is None
    assert parse_scenario({**base, "air_data": {"errors": "typical"}}).air_data.errors == "typical"
    a1 = AirDataComputer.from_spec({"errors": "typical", "seed": 4}).spec
    assert a1 == AirDataComputer.from_spec({"errors": "typical"}, 4).spec
    assert a1 != AirDataComputer.from_spec({"errors": "typical"}, 5).spec
