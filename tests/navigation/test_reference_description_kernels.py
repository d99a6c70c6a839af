"""The compiled pieces of the reference-description monitor equal the plain numpy statements of
the same equations (:func:`propagate`, :func:`channel_filter_step`, :func:`normalised_distance`,
:func:`reference_decision`, F and (Φ, Q_k) from :func:`system_matrix` / :func:`step_discrete`) to
rounding, on realistic matrices (STIM300 and HG1700 models along a turning flight)."""

import numpy as np
import pytest

from fms_testbed.core.state import AircraftState, NavSolution
from fms_testbed.navigation import reference_description as rd
from fms_testbed.navigation.reference_description import (CHANNELS, ReferenceDescriptionMonitor,
                                                           ReferenceTuning, channel_filter_step,
                                                           envelope_start, normalised_distance,
                                                           propagate, reference_decision)
from fms_testbed.sensors.profiles import Segment, aircraft_states, fly_profile
from fms_testbed.sensors.sins.analysis import SinsOptions, step_discrete, system_matrix
from fms_testbed.sensors.sins.presets import load_imu

FREE = SinsOptions(vertical="free")
RTOL = 1e-12


@pytest.fixture(scope="module")
def imus():
    return [load_imu("STIM300"), load_imu("HG1700")]


@pytest.fixture(scope="module")
def truth():
    """A state in a 3 °/s turn (non-zero body rates and lateral specific force)."""
    return aircraft_states(fly_profile([Segment(20.0), Segment(40.0, 3.0)], dt_s=0.1))[500]


def _phi_qk(truth, imu, dt_s=1.0):
    F = system_matrix(truth.lat_rad, truth.alt_m, truth.v_enu_mps,
                      (truth.roll_rad, truth.pitch_rad, truth.heading_rad),
                      (truth.p_rps, truth.q_rps, truth.r_rps), truth.f_body_mps2, imu, FREE)
    return step_discrete(F, imu, dt_s, FREE)


def _spd(rng, n, scale):
    A = rng.standard_normal((n, n)) * scale
    return A @ A.T + np.diag(scale ** 2)


def _envelopes(rng, imu, u):
    scale = np.sqrt(imu.p0_var[:22]) + 1e-6
    return np.stack([envelope_start(_spd(rng, 22, scale), imu) for _ in range(u)])


def test_block_propagation_equals_phi_p_phit_over_many_steps(truth, imus):
    rng = np.random.default_rng(1)
    for imu in imus:
        phi, qk = _phi_qk(truth, imu)
        assert not phi[9:, :9].any() and not (phi[9:, 9:] - np.diag(np.diag(phi[9:, 9:]))).any()
        P = _envelopes(rng, imu, 3)
        P = 0.5 * (P + np.swapaxes(P, 1, 2))
        D = rng.standard_normal((3, 33))
        Pf, Df = P.copy(), D.copy()
        for _ in range(60):                      # a minute of 1-s steps
            P, D = propagate(P, D, phi, qk)      # numpy: all units at once
            for i in range(3):
                rd._propagate_blocks(Pf[i], Df[i], phi, qk)
        np.testing.assert_allclose(Pf, P, rtol=RTOL, atol=0)
        np.testing.assert_allclose(Df, D, rtol=RTOL, atol=0)
        np.testing.assert_array_equal(Pf, np.swapaxes(Pf, 1, 2))


def test_closed_form_channel_filter_equals_the_matrix_form():
    rng = np.random.default_rng(2)
    u, dt = 5, 1.0
    x = rng.standard_normal((u, 2, 2))
    Pc = np.stack([np.stack([_spd(rng, 2, np.array([5.0, 0.1])) for _ in range(2)])
                   for _ in range(u)])
    xf, Pf = x.copy(), Pc.copy()
    r = np.broadcast_to(np.array([[4.0, 0.01], [9.0, 0.04]]), (1, 2, 2))
    for k in range(30):
        z = rng.standard_normal((u, 2, 2)) * [3.0, 0.1]
        q = 10.0 ** rng.uniform(-8, -3, (u, 2))
        x, Pc = channel_filter_step(x, Pc, z, r, q, dt)
        for i in range(u):
            for a in range(2):
                rd._channel_step(xf[i, a], Pf[i, a], z[i, a, 0], z[i, a, 1], r[0, a, 0],
                                 r[0, a, 1], q[i, a], dt)
    np.testing.assert_allclose(xf, x, rtol=RTOL, atol=1e-14)
    np.testing.assert_allclose(Pf, Pc, rtol=RTOL, atol=0)


def test_compiled_measurement_distance_and_decision_equal_the_numpy_statements(truth):
    rng = np.random.default_rng(3)
    u = 3
    mon = ReferenceDescriptionMonitor([load_imu("STIM300")] * u)
    ins = [NavSolution(0.0, truth.lat_rad + 1e-6 * rng.standard_normal(),
                       truth.lon_rad + 1e-6 * rng.standard_normal(), truth.alt_m + 10 * i,
                       truth.v_enu_mps + rng.standard_normal(3), 0.0, 0.0, 0.0)
           for i in range(u)]
    out = (truth.lat_rad, truth.lon_rad, truth.alt_m, truth.v_enu_mps)
    D = rng.standard_normal((u, 33)) * 50.0
    z = np.empty((u, 2, 2))
    a = np.array([[s.lat_rad, s.lon_rad, s.alt_m, s.v_enu_mps[0], s.v_enu_mps[1]] for s in ins])
    s = np.concatenate([out[:3], out[3]])
    rd._measure_into(z, D, a, s)
    np.testing.assert_allclose(z, mon._measure(D, ins, out), rtol=RTOL, atol=0)
    # normalised distance of the oldest window, channel by channel
    P = np.stack([_spd(rng, 33, np.full(33, 2.0)) for _ in range(u)])
    Pc = np.stack([np.stack([_spd(rng, 2, np.ones(2)) for _ in range(2)]) for _ in range(u)])
    x = rng.standard_normal((u, 2, 2)) * 5.0
    e_hat = x.reshape(u, 4)[:, [0, 2, 1, 3]]
    var = P[:, CHANNELS, CHANNELS] + Pc[:, :, [0, 1], [0, 1]].reshape(u, 4)[:, [0, 2, 1, 3]]
    d_ref = normalised_distance(e_hat, var)
    np.testing.assert_allclose([rd._distance(P[i], Pc[i], x[i]) for i in range(u)], d_ref,
                               rtol=RTOL)
    # the decision, including ties (stable ranking), NaN, every unit outside and the latch
    tune = ReferenceTuning()
    cases = [([1.0, 5.0, 2.0], [False] * 3, [np.nan] * 3, 100.0),
             ([5.0, 5.0, 4.5], [False] * 3, [90.0, 95.0, np.nan], 100.0),
             ([6.0, 9.0, 4.5], [False, True, False], [0.0, 0.0, 0.0], 20.0),
             ([2.0, np.nan, 2.0], [False, False, True], [np.nan] * 3, 7.0),
             ([0.5, 0.5, 0.5], [False] * 3, [np.nan] * 3, 0.0)]
    for d, exc, since, t in cases:
        d, exc, since = np.array(d), np.array(exc), np.array(since)
        got = rd._decide(d, exc, since, t, tune.k_sigma, tune.persist_s)
        for g, w in zip(got, reference_decision(d, exc, since, t, tune)):
            np.testing.assert_array_equal(g, w)


def test_one_compiled_epoch_equals_the_numpy_chain(truth, imus):
    """_epoch (two windows, three units on two IMU models) against system_matrix → step_discrete
    → propagate → channel_filter_step → normalised_distance → reference_decision."""
    rng = np.random.default_rng(4)
    unit_imus = [imus[0], imus[1], imus[0]]
    mon = ReferenceDescriptionMonitor(unit_imus)
    u, dt, t = 3, 1.0, 500.0
    P = np.stack([np.stack([envelope_start(_spd(rng, 22, np.sqrt(imu.p0_var[:22]) + 1e-6), imu)
                            for imu in unit_imus]) for _ in range(2)])
    P = 0.5 * (P + np.swapaxes(P, -1, -2))
    D = rng.standard_normal((2, u, 33)) * 10.0
    X = rng.standard_normal((2, u, 2, 2))
    PC = np.stack([np.stack([np.stack([_spd(rng, 2, np.array([3.0, 0.1])) for _ in range(2)])
                             for _ in range(u)]) for _ in range(2)])
    ins = rng.standard_normal((u, 5)) * [1e-6, 1e-6, 5.0, 0.5, 0.5] + [
        truth.lat_rad, truth.lon_rad, truth.alt_m, truth.v_enu_mps[0], truth.v_enu_mps[1]]
    P_out = _spd(rng, 6, np.array([2.0, 2.0, 3.0, 0.1, 0.1, 0.1]))
    s = np.array([truth.lat_rad, truth.lon_rad, truth.alt_m, *truth.v_enu_mps, truth.roll_rad,
                  truth.pitch_rad, truth.heading_rad, truth.p_rps, truth.q_rps, truth.r_rps,
                  *truth.f_body_mps2, P_out[0, 0], P_out[3, 3], P_out[1, 1], P_out[4, 4], dt, t])
    excluded, since = np.array([False, False, False]), np.array([np.nan, 495.0, np.nan])
    detected = np.zeros(u, bool)
    slots = np.array([1, 0])                                  # slot 1 is the older window
    want = {k: v.copy() for k, v in (("P", P), ("D", D), ("X", X), ("PC", PC))}
    s_long = s.copy()
    s_long[19] = 1e5                     # Δt/τ beyond the Picard range: refused, nothing touched
    assert rd._epoch(P, D, X, PC, slots, s_long, ins, mon._decay, mon._q_psd, mon._model,
                     FREE.tol, excluded, since, detected, 4.0, 10.0, 10.0)[0] == 1
    np.testing.assert_array_equal(P, want["P"])
    status, d, used, exc, since_n, rank, notify, all_out = rd._epoch(
        P, D, X, PC, slots, s, ins, mon._decay, mon._q_psd, mon._model, FREE.tol, excluded,
        since, detected, 4.0, 10.0, 10.0)
    assert status == 0
    r = mon._r(P_out)
    out = (s[0], s[1], s[2], s[3:6])
    sols = [NavSolution(0.0, *ins[i, :3], np.array([ins[i, 3], ins[i, 4], 0.0]), 0.0, 0.0, 0.0)
            for i in range(u)]
    for w in slots:
        v0 = want["P"][w][:, [3, 4], [3, 4]].copy()
        for i, imu in enumerate(unit_imus):
            phi, qk = _phi_qk(truth, imu, dt)
            Pi, Di = propagate(want["P"][w][i:i + 1], want["D"][w][i:i + 1], phi, qk)
            want["P"][w][i], want["D"][w][i] = Pi[0], Di[0]
        vv = want["P"][w][:, [3, 4], [3, 4]]
        q = np.maximum(np.maximum((vv - v0) / dt, vv / 10.0), 1e-10)
        want["X"][w], want["PC"][w] = channel_filter_step(
            want["X"][w], want["PC"][w], mon._measure(want["D"][w], sols, out), r, q, dt)
    for k, got in (("P", P), ("D", D), ("X", X), ("PC", PC)):
        np.testing.assert_allclose(got, want[k], rtol=RTOL, atol=0, err_msg=k)
    w = slots[0]
    e_hat = want["X"][w].reshape(u, 4)[:, [0, 2, 1, 3]]
    var = (want["P"][w][:, CHANNELS, CHANNELS]
           + want["PC"][w][:, :, [0, 1], [0, 1]].reshape(u, 4)[:, [0, 2, 1, 3]])
    d_ref = normalised_distance(e_hat, var)
    np.testing.assert_allclose(d, d_ref, rtol=RTOL)
    for g, ref in zip((used, exc, since_n, rank),
                      reference_decision(d_ref, excluded, since, t, ReferenceTuning())):
        np.testing.assert_array_equal(g, ref)
    assert notify == bool(((d_ref > 4.0) & ~detected).any())
