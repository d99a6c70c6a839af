"""Three INS with seed 001's two-stage identification, fault injection, the majority-voting
baseline, and the scenario's fault block."""

import math

import numpy as np
import pytest

from fms_testbed.config.scenario import parse_scenario
from fms_testbed.core.errors import ConfigError, UserError
from fms_testbed.navigation import make_source
from fms_testbed.navigation.fdi import MAJORITY, FdiTuning, SensorComparator, channel_sigmas
from fms_testbed.run import run_scenario
from fms_testbed.sensors.profiles import Segment, aircraft_states, fly_profile

Q_STIM = np.r_[[(0.06 / 60) ** 2] * 3, [(math.radians(0.15) / 60) ** 2] * 3]


@pytest.fixture(scope="module")
def states():
    segs = [Segment(100.0), Segment(40.0, 3.0), Segment(80.0), Segment(40.0, -2.0, 3.0),
            Segment(60.0)]
    return aircraft_states(fly_profile(segs, dt_s=0.1, speed_mps=150.0))


def _fly(states, fault=None, at_s=150.0, seed=0, n_ins=3):
    nav = make_source({"source": "ins_gnss", "imu": "STIM300", "n_ins": n_ins}, seed=seed)
    sols = []
    for s in states:
        sols.append(nav.update(s))
        if fault is not None and abs(s.t_s - at_s) < 1e-6:
            nav.inject(fault, s.t_s)
    return nav, sols


def _first(nav, kind, unit_prefix="ins"):
    t = [e["t_s"] for e in nav.events if e["kind"] == kind and e["unit"].startswith(unit_prefix)]
    return t[0] if t else None


def test_majority_table_is_seed_001s():
    assert MAJORITY == {(1, 1, 0): 0, (1, 0, 1): 1, (0, 1, 1): 2}


def test_channel_sigmas_carry_the_unmodelled_attitude_error():
    """Tilt σ² = P + var_a n² + var_g (φ² + θ²), heading σ² = P + var_g (φ² + θ²); position and
    velocity σ are the filter's; without the declared variances nothing is added."""
    P = np.diag(np.arange(1.0, 16.0)) * 1e-8
    base = channel_sigmas(P)
    assert base[6] == base[7] == pytest.approx(math.sqrt(8e-8))
    var_a, var_g, roll, pitch, n = 2.3e-6, 2.25e-6, math.radians(30), math.radians(5), 1.15
    d = channel_sigmas(P, (var_a, var_g), roll, pitch, n)
    np.testing.assert_array_equal(d[:6], base[:6])
    rot2 = var_g * (roll ** 2 + pitch ** 2)
    assert d[6] == d[7] == pytest.approx(math.sqrt(8e-8 + var_a * n ** 2 + rot2), rel=1e-12)
    assert d[8] == pytest.approx(math.sqrt(9e-8 + rot2), rel=1e-12)


def test_sensor_comparator_flags_the_pairs_of_the_stepped_unit_and_nothing_when_healthy():
    rng = np.random.default_rng(0)
    dt = 0.1
    comp = SensorComparator(3, np.tile(Q_STIM, (3, 1)), dt, np.zeros((3, 2)))
    sig = np.sqrt(Q_STIM / dt)
    nus = []
    for k in range(1500):
        t = k * dt
        e = sig * rng.standard_normal((3, 6)) + np.array([1e-3, 0, 0, 2e-6, 0, 0]) * np.arange(3)[:, None]
        if t >= 100.0:
            e[1, 0] += 3750e-6 * 9.80665                     # 5σ of the 750 µg turn-on bias
        nus.append(comp.update(t, e, np.array([0, 0, -9.8]), np.zeros(3)))
    nus = np.array(nus)
    assert not nus[:1000].any()                              # healthy: constant offsets only
    first = np.argmax(nus.any(axis=1)) * dt
    assert 100.0 <= first <= 101.0 and tuple(nus[1005]) == (1, 0, 1)


def test_fault_free_flight_has_no_identification_events(states):
    nav, sols = _fly(states)
    assert nav.events == []
    assert {s.errors["ins_used"] for s in sols} == {7.0}


def test_accelerometer_bias_step_of_5_sigma_is_detected_and_isolated_to_its_unit(states):
    """Stage 1 (sensor level) names INS 2 by table 1: it leaves the output at once; no other
    unit is isolated or excluded."""
    fault = {"unit": "ins2", "kind": "accel_bias_step", "axis": "x", "size_ug": 3750.0}
    nav, sols = _fly(states, fault, at_s=150.0)
    det, iso = _first(nav, "detected"), _first(nav, "isolated")
    assert det is not None and det - 150.0 <= 10.0
    assert iso is not None and iso - 150.0 <= 30.0
    assert {e["unit"] for e in nav.events if e["kind"] in ("isolated", "excluded")} == {"ins2"}
    assert sols[-1].errors["ins_used"] == 5.0                  # ins1 + ins3
    nse = max(math.hypot(s.errors["nse_east_m"], s.errors["nse_north_m"]) for s in sols[1500:])
    assert nse < 5.0


def test_stuck_output_is_excluded_within_two_seconds(states):
    nav, sols = _fly(states, {"unit": "ins3", "kind": "stuck"}, at_s=150.0, seed=2)
    exc = [(e["t_s"], e["unit"]) for e in nav.events if e["kind"] == "excluded"]
    assert exc and exc[0][1] == "ins3" and exc[0][0] - 150.0 <= 2.0
    assert any(e["kind"] == "fault_injected" for e in nav.events)


def test_voting_baseline_is_logged_next_to_the_identified_output(states):
    _, sols = _fly(states[:600])
    assert {"nse_vote_east_m", "nse_vote_north_m", "fdi_nu"} <= set(sols[-1].errors)


@pytest.mark.parametrize("fault, msg", [
    ({"unit": "gnss", "kind": "gyro_bias_step", "axis": "x", "size_dph": 1}, "ins1..ins3"),
    ({"unit": "ins1", "kind": "gyro_bias_step", "axis": "x"}, "size_dph"),
    ({"unit": "ins1", "kind": "gnss_outage"}, "gnss"),
    ({"unit": "baro", "kind": "baro_failure", "bogus": 1}, "bogus"),
])
def test_fault_blocks_are_validated(fault, msg):
    raw = {"aircraft": "737", "duration_s": 10,
           "initial": {"alt_m": 3000, "tas_mps": 150}, "events": [{"t_s": 1, "fault": fault}]}
    with pytest.raises(ConfigError, match=msg):
        parse_scenario(raw)


def _cruise(nav, faults, duration_s=40):
    return {"aircraft": "737", "duration_s": duration_s, "hold": True,
            "initial": {"lat_deg": 47.0, "lon_deg": 8.0, "alt_m": 3000, "tas_kmh": 400},
            "navigation": nav, "events": [{"t_s": 20, "fault": f} for f in faults]}


def test_a_fault_needs_a_source_that_takes_it():
    with pytest.raises(UserError, match="events.fault"):
        run_scenario(_cruise({"source": "sins", "imu": "STIM300"},
                             [{"unit": "gnss", "kind": "gnss_outage"}]), progress=False)
    with pytest.raises(ConfigError, match="n_ins is 1"):
        run_scenario(_cruise({"source": "ins_gnss", "imu": "STIM300"},
                             [{"unit": "ins3", "kind": "stuck"}]), progress=False)


def test_gnss_outage_and_baro_failure_events_reach_the_summary():
    res = run_scenario(_cruise({"source": "ins_gnss", "imu": "STIM300"},
                               [{"unit": "gnss", "kind": "gnss_outage", "duration_s": 10},
                                {"unit": "baro", "kind": "baro_failure"}]), progress=False)
    ev = res.summary["navigation"]["events"]
    assert [e["kind"] for e in ev[:2]] == ["fault_injected", "fault_injected"]
    assert all(set(e) == {"t_s", "unit", "kind", "stage", "reason"} for e in ev)
    df = res.df
    assert (df["nav_mode"][(df["t_s"] > 23) & (df["t_s"] < 30)] == 1).all()
    assert (df["nav_mode"][df["t_s"] > 33] == 0).all()


@pytest.mark.slow
def test_voting_on_raw_outputs_keeps_a_calibrated_drift_and_drops_a_large_step(states):
    """Majority voting on the free units (no feedback): a drift ×2 (0.5 °/h excess, inside the
    declared free-inertial σ) stays in; a 2,000 °/h gyro step leaves the raw output's attitude
    beyond k_pair √2 σ_free within seconds and is voted out, while the corrected outputs of the
    filters (which calibrate it) are what the identified output uses."""
    nav = make_source({"source": "ins_gnss", "imu": "STIM300", "n_ins": 3}, seed=3)
    votes, ts = [], []
    for s in states[:1500]:
        e = nav.update(s).errors
        votes.append(int(e["ins_used_vote"]))
        ts.append(s.t_s)
        if abs(s.t_s - 20.0) < 1e-6:
            nav.inject({"unit": "ins2", "kind": "drift_scale", "factor": 2.0}, s.t_s)
        if abs(s.t_s - 100.0) < 1e-6:
            nav.inject({"unit": "ins3", "kind": "gyro_bias_step", "axis": "y",
                        "size_dph": 2000.0}, s.t_s)
    ts, votes = np.array(ts), np.array(votes)
    assert set(votes[ts < 100.0]) == {7}                       # the drift ×2 unit voted in
    assert set(votes[ts > 110.0]) == {3}                       # ins3 out, ins1 + ins2 in
    # the vote is on the raw outputs: the free unit 3 is far from its corrected twin
    raw, cor = nav._free_out[2], nav.bank.output(2, states[1499])
    assert abs(raw.pitch_rad - cor.pitch_rad) > math.radians(0.5)
