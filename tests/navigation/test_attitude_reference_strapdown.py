"""Seed 004's flight-test mode on the strapdown truth: the computer mechanises the measured
accelerometer increments with the reference's angles; checked against the true trajectory, the
physics of a tilt error (g δγ t), the linear model on the same injected errors, and a flight in
which the filter and the computer never read the true state."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fms_testbed.core.earth import radii_m
from fms_testbed.data import scenarios_dir
from fms_testbed.navigation import attitude_reference as ar
from fms_testbed.navigation import make_source
from fms_testbed.run import run_scenario
from fms_testbed.sensors.attitude_reference import (AttitudeReferenceSpec, FlightTestErrors,
                                                    FlightTestSensors)
from fms_testbed.sensors.profiles import Segment, aircraft_states, fly_profile
from fms_testbed.sensors.sins.presets import load_imu
from tests.navigation.test_filter_never_reads_truth import _poisoned

IDEAL = {"name": "ideal", "gyro": {"arw_deg_per_sqrt_h": 0.0},
         "accelerometer": {"vrw_mps_per_sqrt_h": 0.0}}
Z3 = (0.0, 0.0, 0.0)


def _spec(bias_rad=Z3):
    return AttitudeReferenceSpec(Z3, Z3, bias_rad=bias_rad, drift_rps=Z3)


def _states(segments):
    return list(aircraft_states(fly_profile(segments, dt_s=0.1, speed_mps=120.0,
                                            heading_deg=30.0)))


def _errors(comp, s):
    lat, lon, alt, v = comp.computer_position()
    rm, rn = radii_m(s.lat_rad)
    dp = np.array([(lon - s.lon_rad) * (rn + s.alt_m) * math.cos(s.lat_rad),
                   (lat - s.lat_rad) * (rm + s.alt_m), alt - s.alt_m])
    return dp, np.asarray(v) - s.v_enu_mps


def _max_errors(comp, states):
    mp = mv = 0.0
    for s in states:
        comp.update(s)
        dp, dv = _errors(comp, s)
        mp, mv = max(mp, np.abs(dp).max()), max(mv, np.abs(dv).max())
    return mp, mv


TURNS_CLIMB = [Segment(5), Segment(40, 3.0), Segment(30, -3.0, 2.0), Segment(40)]


def test_error_free_sensors_keep_the_computer_on_the_trajectory():
    # turns at 3 °/s and a climb: rotation and sculling terms matter, gravity and Coriolis too
    comp = ar.FlightTestComputer(FlightTestSensors(_spec(), IDEAL, 1), 2, 0.0, 0.0)
    mp, mv = _max_errors(comp, _states(TURNS_CLIMB))
    assert mp < 0.01 and mv < 1e-5


def test_without_the_body_rotation_the_turns_show(monkeypatch):
    # the check above has teeth: drop the rotation the angle samples imply and the velocity
    # error in the turns is tenths of m/s
    monkeypatch.setattr(ar, "inverse_step", lambda row, v, q, dt: ((0.0, 0.0, 0.0), None))
    comp = ar.FlightTestComputer(FlightTestSensors(_spec(), IDEAL, 1), 2, 0.0, 0.0)
    assert _max_errors(comp, _states(TURNS_CLIMB))[1] > 0.1


LEVER_M = (12.0, -1.5, 2.0)


def _velocity_errors(comp, states):
    out = []
    for s in states:
        comp.update(s)
        out.append((s.t_s, *_errors(comp, s)))
    return out


def test_accelerometers_off_the_cg_are_compensated_by_the_computer():
    # the block 12 m ahead of the CG: it senses the turns' centripetal and tangential
    # accelerations and moves with ω × l; the computer mechanises the IMU point and moves its
    # output to the CG
    states = _states(TURNS_CLIMB)
    comp = ar.FlightTestComputer(FlightTestSensors(_spec(), IDEAL, 1), 2, 0.0, 0.0)
    comp.set_lever_arm(LEVER_M)
    assert any("p-rad_sec" in p for p, _ in comp.frame_properties)
    rows = _velocity_errors(comp, states)
    assert max(np.abs(dp).max() for _, dp, _ in rows) < 0.05
    # ω_eb is the angle samples' mean over the step: it lags the sampled rate by half a step
    # while the roll rate changes; in steady flight and steady turns the output is exact
    steady = [dv for t, _, dv in rows if 55 <= t <= 74 or t >= 90]
    assert max(np.abs(dv).max() for dv in steady) < 1e-3


def test_without_the_lever_arm_compensation_the_output_is_off_by_the_lever_arm():
    comp = ar.FlightTestComputer(FlightTestSensors(_spec(), IDEAL, 1), 2, 0.0, 0.0)
    comp.set_lever_arm(LEVER_M, compensate=False)
    rows = _velocity_errors(comp, _states(TURNS_CLIMB))
    assert max(np.abs(dp).max() for _, dp, _ in rows) > 10.0
    steady = [dv for t, _, dv in rows if 55 <= t <= 74]              # the 3 °/s turn
    assert max(np.abs(dv).max() for dv in steady) > 0.3             # |ω × l| ≈ 0.05 × 12


def test_the_source_installs_the_aircraft_lever_arm_in_the_strapdown_mode():
    src = make_source({"source": "attitude_reference", "truth_model": "strapdown"}, seed=3)
    src.install_imu(LEVER_M)
    assert np.allclose(src.errors.lever, LEVER_M)
    assert np.allclose(src.errors.sensors.lever_arm_m, LEVER_M)
    assert any("r-rad_sec" in p for p, _ in src.frame_properties)


def test_a_roll_error_tilts_gravity_into_the_velocity_as_the_linear_model_says():
    d_roll = math.radians(0.05)
    states = _states([Segment(30)])
    comp = ar.FlightTestComputer(FlightTestSensors(_spec((d_roll, 0, 0)), IDEAL, 1), 2, 0, 0)
    lin = FlightTestErrors(_spec((d_roll, 0, 0)), load_imu(IDEAL), 3, 0.0, 0.0)
    for s in states:
        comp.update(s)
        lin.update(s)
    _, dv = _errors(comp, states[-1])
    g_t = 9.80 * d_roll * states[-1].t_s            # |δV| = g δγ t (Schuler: 1e-4 at 30 s)
    assert math.hypot(dv[0], dv[1]) == pytest.approx(g_t, rel=3e-3)
    np.testing.assert_allclose(dv[:2], lin.x[3:5], atol=2e-4 * g_t)


def test_the_accelerometer_block_errors_reach_the_computer():
    # HG9900 (25 µg turn-on bias, 100 ppm scale factor): metres, not millimetres, in 60 s free
    comp = ar.FlightTestComputer(FlightTestSensors(_spec(), "HG9900", 1), 2, 0.0, 0.0)
    sens = comp.sensors
    comp.update(_states([Segment(1)])[0])
    b = sens.accel.values(0)[:3]
    assert 0 < np.abs(b).max() < 5 * 25e-6 * 9.81
    mp, _ = _max_errors(comp, _states([Segment(60)])[1:])
    assert mp > 0.01


def test_a_flight_runs_with_filter_and_computer_poisoned(monkeypatch):
    for cls, names in ((ar.AttitudeReferenceFilter, ("predict", "gnss_update", "take_feedback")),
                       (ar.FlightTestComputer, ("reset", "specific_force_mps2",
                                                "computer_position", "computer_angles"))):
        for n in names:
            monkeypatch.setattr(cls, n, _poisoned(getattr(cls, n)))
    res = run_scenario(scenarios_dir() / "flight-test-attitude.yaml", seed=1, progress=False,
                       overrides={"duration_s": 70})
    s = res.summary
    assert s["status"] == "ok" and s["navigation"]["truth_model"] == "strapdown"
    h = s["attitude_reference"]["angles"]["heading"]
    assert h["sigma_at_s_deg"] < 0.03 and h["inside_3sigma"]


def test_linear_is_kept_as_the_fast_mode():
    a = make_source({"source": "attitude_reference"}, seed=0)
    b = make_source({"source": "attitude_reference", "truth_model": "linear"}, seed=0)
    assert (a.truth_model, b.truth_model) == ("strapdown", "linear")
    assert a.frame_properties and not b.frame_properties


def test_the_reference_random_walks_have_their_declared_variance():
    # θ(t) - θ0 - d0 t has variance N_θ² t + N_d² t³/3 (angle and drift random walks), d(t) - d0
    # variance N_d² t: 800 realisations of 25 steps of 0.4 s against the formula (3σ bounds)
    from fms_testbed.sensors.attitude_reference import ReferenceAngleErrors
    n_t, n_d = 1e-3, 2e-4
    spec = AttitudeReferenceSpec((0.01,) * 3, (1e-4,) * 3, (n_t,) * 3, (n_d,) * 3)
    th, dr = [], []
    for k in range(800):
        r = ReferenceAngleErrors(spec, np.random.default_rng(k))
        t0, d0 = r.theta_rad.copy(), r.drift_rps.copy()
        for _ in range(25):
            r.advance(0.4)
        th.append(r.theta_rad - t0 - d0 * 10.0)
        dr.append(r.drift_rps - d0)
    th, dr = np.array(th), np.array(dr)
    np.testing.assert_allclose(th.var(axis=0), n_t ** 2 * 10 + n_d ** 2 * 1000 / 3, rtol=0.16)
    np.testing.assert_allclose(dr.var(axis=0), n_d ** 2 * 10, rtol=0.16)
    np.testing.assert_allclose(np.mean(th * dr, axis=0), n_d ** 2 * 100 / 2, rtol=0.2)
