"""GNSS receiver and baro on the truth side: error statistics, timing, faults, seeding."""

import math

import numpy as np
import pytest

from fms_testbed.core.earth import radii_m
from fms_testbed.core.errors import ConfigError
from fms_testbed.sensors.baro import BaroAltimeter, BaroSpec
from fms_testbed.sensors.gnss import GnssReceiver, GnssSpec, Interval, OutlierBurst, Ramp
from fms_testbed.sensors.profiles import Segment, aircraft_states, fly_profile


@pytest.fixture(scope="module")
def states():
    return aircraft_states(fly_profile([Segment(40.0)], dt_s=0.1))


def _fixes(spec, states, seed=0):
    rx = GnssReceiver(spec, seed)
    out = []
    for s in states:
        out += [(s.t_s, f) for f in rx.update(s)]
    return out


def test_fixes_come_at_the_rate_and_are_delivered_after_the_latency(states):
    got = _fixes(GnssSpec(rate_hz=2.0, latency_s=0.3), states)
    t_valid = np.array([f.t_s for _, f in got])
    assert np.allclose(np.diff(t_valid), 0.5)
    for t_now, f in got:
        assert f.t_delivered_s == pytest.approx(f.t_s + 0.3)
        assert t_now >= f.t_delivered_s - 1e-9 and t_now - f.t_delivered_s < 0.1 + 1e-9


def test_fix_is_truth_plus_its_error_in_enu_metres(states):
    by_t = {s.t_s: s for s in states}
    for _, f in _fixes(GnssSpec(), states, seed=4)[:10]:
        s = by_t[f.t_s]
        rm, rn = radii_m(s.lat_rad)
        assert (f.lat_rad - s.lat_rad) * (rm + s.alt_m) == pytest.approx(f.err_enu_m[1], rel=1e-6)
        assert (f.lon_rad - s.lon_rad) * (rn + s.alt_m) * math.cos(s.lat_rad) == pytest.approx(
            f.err_enu_m[0], rel=1e-6)
        assert np.allclose(f.v_enu_mps - s.v_enu_mps, f.err_v_enu_mps)


def test_markov_errors_have_their_sigma_and_correlation_time():
    # exact discretisation: stationary σ and lag-1 correlation e^{-Δt/τ}, over many epochs
    spec = GnssSpec(pos_markov_sigma_m=(2.0, 2.0, 3.0), pos_markov_tau_s=20.0)
    rx = GnssReceiver(spec, seed=9)
    m = []
    for k in range(20000):
        rx._propagate_markov(float(k))
        m.append(rx.markov[:3].copy())
    m = np.array(m)
    assert m.std(axis=0) == pytest.approx([2.0, 2.0, 3.0], rel=0.06)
    r1 = np.corrcoef(m[:-1, 0], m[1:, 0])[0, 1]
    assert r1 == pytest.approx(math.exp(-1 / 20.0), abs=0.01)


def test_outage_outlier_burst_and_ramp(states):
    spec = GnssSpec(outages=(Interval(10.0, 15.0),),
                    outliers=(OutlierBurst(Interval(20.0, 25.0), 50.0),),
                    ramps=(Ramp(Interval(30.0), (0.5, 0.0, 0.0)),))
    got = [f for _, f in _fixes(spec, states, seed=1)]
    clean = [f for _, f in _fixes(GnssSpec(), states, seed=1)]
    assert not [f for f in got if 10.0 <= f.t_s < 15.0]
    same = {f.t_s: f for f in clean}
    burst = [np.abs(f.err_enu_m - same[f.t_s].err_enu_m).max() for f in got if 20 <= f.t_s < 25]
    assert max(burst) > 20.0                       # 50 m σ outliers
    for f in got:
        if f.t_s >= 30.0:
            assert f.err_enu_m[0] - same[f.t_s].err_enu_m[0] == pytest.approx(0.5 * (f.t_s - 30))
        elif not 20 <= f.t_s < 25:                 # faults leave the other draws alone
            assert np.array_equal(f.err_enu_m, same[f.t_s].err_enu_m)


def test_latency_must_stay_below_the_fix_period():
    with pytest.raises(ConfigError, match="latency_s"):
        GnssSpec(rate_hz=1.0, latency_s=1.0)


def test_baro_bias_statistics_and_stuck_port(states):
    spec = BaroSpec(markov_sigma_m=4.0, markov_tau_s=50.0, white_sigma_m=0.0, rate_hz=10.0)
    biases = []
    for sd in range(400):
        b = BaroAltimeter(spec, sd)
        biases.append(b.update(states[0]).err_m)
    assert np.std(biases) == pytest.approx(4.0, rel=0.1)
    stuck = BaroAltimeter(BaroSpec(failed_from_s=10.0), 0)
    readings = [stuck.update(s) for s in states]
    frozen = [r.alt_m for r in readings if r is not None and r.t_s >= 10.0]
    assert len(set(frozen)) == 1
    assert [r.t_s for r in readings if r is not None][:3] == [0.0, pytest.approx(1.0),
                                                              pytest.approx(2.0)]
