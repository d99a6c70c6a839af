"""The 33-state F against the nonlinear mechanisation and the textbook free-inertial behaviour."""

import math

import numpy as np
import pytest
import scipy.linalg

from fms_testbed.core.earth import A_M, radii_m
from fms_testbed.core.units import G0_MPS2
from fms_testbed.sensors.sins.discretize import discretize
from fms_testbed.sensors.sins.model import baro_gains, build_F, dcm_body_to_enu, gravity_up, mechanisation_rates

LAT, ALT = 0.82, 3000.0
V = np.array([150.0, 100.0, 5.0])
C = dcm_body_to_enu(0.3, 0.05, 1.0)
F_B = np.array([0.5, 0.3, -10.2])
W_IB = np.array([0.01, -0.02, 0.05])
DECAY = np.zeros(24)


def _skew(v):
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def _T(lat, h):
    rm, rn = radii_m(lat)
    return np.array([[0.0, (rn + h) * math.cos(lat), 0.0], [rm + h, 0.0, 0.0], [0.0, 0.0, 1.0]])


TRUTHS = {
    # name: (lat rad, alt m, V ENU m/s, C_B^N, specific force FRD m/s², ω_IB FRD rad/s)
    "climbing-turn-47N": (LAT, ALT, V, C, F_B, W_IB),
    "descent-southern-banked": (-0.6, 9000.0, np.array([-220.0, 40.0, -12.0]),
                                dcm_body_to_enu(-0.5, -0.03, 4.2), np.array([-0.8, 0.1, -12.5]),
                                np.array([-0.03, 0.01, -0.08])),
    "low-slow-60N": (1.05, 300.0, np.array([20.0, -60.0, 2.0]), dcm_body_to_enu(0.05, 0.12, 2.9),
                     np.array([1.2, -0.2, -9.6]), np.array([0.002, 0.004, -0.01])),
}


def _sensor_errors(x, a, w):
    ba, bg, ka, kg, ma, mg = x[9:12], x[12:15], x[15:18], x[18:21], x[21:27], x[27:33]
    da = ba + ka * a + np.array([a[1] * ma[0] + a[2] * ma[1], a[0] * ma[2] + a[2] * ma[3],
                                 a[0] * ma[4] + a[1] * ma[5]])
    dw = bg + kg * w + np.array([w[1] * mg[0] + w[2] * mg[1], w[0] * mg[2] + w[2] * mg[3],
                                 w[0] * mg[4] + w[1] * mg[5]])
    return da, dw


def _error_rate(x, truth):
    """dx/dt of the navigation errors (9) from the exact mechanisation of truth and perturbed."""
    lat, alt, v, c, f_b, w_ib = truth
    T = _T(lat, alt)
    dr = np.linalg.solve(T, x[0:3])                       # (δφ, δλ, δh)
    c_s = scipy.linalg.expm(-_skew(x[6:9])) @ c
    da, dw = _sensor_errors(x, f_b, w_ib)
    rt = mechanisation_rates(lat, alt, v, c, f_b, w_ib)
    rs = mechanisation_rates(lat + dr[0], alt + dr[2], v + x[3:6], c_s, f_b + da, w_ib + dw)
    # δp = T(r) (r* - r):  d/dt δp = Ṫ (r* - r) + T (ṙ* - ṙ), Ṫ by central differences in φ, h
    e = 1e-6
    dT_dlat = (_T(lat + e, alt) - _T(lat - e, alt)) / (2 * e)
    dT_dh = (_T(lat, alt + 1.0) - _T(lat, alt - 1.0)) / 2.0
    T_dot = dT_dlat * rt[0] + dT_dh * rt[2]
    dp_dot = T_dot @ dr + T @ np.array([rs[0] - rt[0], rs[1] - rt[1], rs[2] - rt[2]])
    dv_dot = rs[3] - rt[3]
    e_dot_m = rs[4] @ c.T + c_s @ rt[4].T                  # d/dt (C* Cᵀ)
    sk = 0.5 * (e_dot_m - e_dot_m.T)
    eps_dot = -np.array([sk[2, 1], sk[0, 2], sk[1, 0]])
    return np.concatenate([dp_dot, dv_dot, eps_dot])


@pytest.mark.parametrize("name", list(TRUTHS))
def test_F_matches_numerical_jacobian_of_mechanisation_to_1e6(name):
    truth = TRUTHS[name]
    lat, alt, v, c, f_b, w_ib = truth
    F = build_F(lat, alt, v, f_b, w_ib, c, DECAY, 0.0, 0.0)
    steps = np.array([10.0] * 3 + [1e-2] * 3 + [1e-5] * 3 + [1e-4] * 3 + [1e-6] * 3
                     + [1e-4] * 6 + [1e-4] * 12)
    J = np.zeros((9, 33))
    for j in range(33):
        xp = np.zeros(33)
        xp[j] = steps[j]
        J[:, j] = (_error_rate(xp, truth) - _error_rate(-xp, truth)) / (2 * steps[j])
    Fn = F[:9]
    scale = np.abs(J).max(axis=1, keepdims=True)          # row scale (units differ per row)
    err = np.abs(Fn - J)
    assert np.all(err <= 1e-6 * np.maximum(np.abs(J), 1e-6 * scale)), np.unravel_index(
        np.argmax(err / np.maximum(np.abs(J), 1e-6 * scale)), err.shape)
    assert np.array_equal(np.diag(F)[9:], -DECAY)


def _stationary_F(lat=math.radians(45.0), heading=math.pi / 2, baro_tau_s=60.0):
    """F of a level aircraft at rest, heading east. The vertical channel is baro-damped by
    default: free, its exponential growth leaks into the horizontal channels through the
    Coriolis terms (2Ω cos φ) and spoils the single-axis formulas within the hour."""
    c = dcm_body_to_enu(0.0, 0.0, heading)
    g = -gravity_up(lat, 0.0)[0]
    f_b = c.T @ np.array([0.0, 0.0, g])
    w_ib = c.T @ (7.292115e-5 * np.array([0.0, math.cos(lat), math.sin(lat)]))
    k1, k2 = baro_gains(baro_tau_s, lat)
    return build_F(lat, 0.0, np.zeros(3), f_b, w_ib, c, DECAY, k1, k2), c, g


def test_schuler_foucault_and_vertical_instability_from_eigenvalues():
    lat = math.radians(45.0)
    F, _, g = _stationary_F(lat, baro_tau_s=None)   # Schuler splits by ± Ω sin φ
    ev = np.linalg.eigvals(F[:9, :9])
    rm, rn = radii_m(lat)
    w_s = math.sqrt(g / math.sqrt(rm * rn))
    period_min = 2 * math.pi / w_s / 60
    assert period_min == pytest.approx(84.4, rel=0.01)
    osc = np.sort(np.abs(ev.imag[ev.imag > 1e-4]))
    w_f = 7.292115e-5 * math.sin(lat)
    assert osc[0] == pytest.approx(w_s - w_f, rel=2e-3)
    assert osc[-1] == pytest.approx(w_s + w_f, rel=2e-3)
    growth = ev.real.max()
    assert growth == pytest.approx(math.sqrt(2 * g / A_M), rel=0.01)   # e-folding ≈ 570 s
    assert 1 / growth == pytest.approx(570, rel=0.02)


def _propagate(F, x0, t_end_s, dt=1.0):
    phi, _ = discretize(F, np.zeros_like(F), dt, method="vanloan")
    n = int(t_end_s / dt)
    out = np.empty((n + 1, x0.size))
    out[0] = x0
    for k in range(n):
        out[k + 1] = phi @ out[k]
    return np.arange(n + 1) * dt, out


def _close(actual, formula, rel):
    # within rel of the formula over the hour, measured against the formula's peak magnitude
    return np.abs(actual - formula).max() <= rel * np.abs(formula).max()


def test_single_axis_accelerometer_bias_gives_schuler_bowl_within_10pct():
    F, c, g = _stationary_F()
    w_s = math.sqrt(g / A_M)
    b = 1e-3 * G0_MPS2                                           # 1 mg on body x (east)
    x0 = np.zeros(33)
    x0[9] = b
    t, x = _propagate(F, x0, 3600.0)
    formula = b * (1 - np.cos(w_s * t)) / w_s ** 2
    assert _close(x[:, 0], formula, 0.10)
    assert x[:, 0].max() == pytest.approx(2 * b * A_M / g, rel=0.10)   # peak 2bR/g ≈ 12.7 km


def test_single_axis_tilt_within_10pct():
    F, c, g = _stationary_F()
    w_s = math.sqrt(g / A_M)
    x0 = np.zeros(33)
    x0[7] = 1e-3                                             # 1 mrad about north
    t, x = _propagate(F, x0, 3600.0)
    formula = -A_M * 1e-3 * (1 - np.cos(w_s * t))            # δV_E' = -g ε_N
    assert _close(x[:, 0], formula, 0.10)


def test_single_axis_gyro_drift_within_10pct():
    F, c, g = _stationary_F()
    w_s = math.sqrt(g / A_M)
    drift = math.radians(0.01) / 3600                        # 0.01 °/h
    bg = c.T @ np.array([0.0, -drift, 0.0])                  # ε_N' = -(C b_g)_N = +drift
    x0 = np.zeros(33)
    x0[12:15] = bg
    t, x = _propagate(F, x0, 3600.0)
    formula = -A_M * drift * (t - np.sin(w_s * t) / w_s)
    assert _close(x[:, 0], formula, 0.10)
    assert abs(x[-1, 0]) == pytest.approx(1350, rel=0.10)    # ≈ 1.35 km after 1 h


def test_initial_velocity_error_oscillates_at_schuler_frequency():
    F, c, g = _stationary_F()
    w_s = math.sqrt(g / A_M)
    x0 = np.zeros(33)
    x0[3] = 1.0
    t, x = _propagate(F, x0, 3600.0)
    assert _close(x[:, 0], np.sin(w_s * t) / w_s, 0.10)


def test_white_noise_growth_matches_short_time_formulas():
    F, c, g = _stationary_F()
    n_a, n_g = 1e-3, 1e-5                                    # m/s/√s, rad/√s
    q = np.zeros(33)
    q[3:6], q[6:9] = n_a ** 2, n_g ** 2
    P = np.zeros((33, 33))
    phi, qk = discretize(F, np.diag(q), 0.1)
    for _ in range(600):                                     # 60 s
        P = phi @ P @ phi.T + qk
    t = 60.0
    assert P[3, 3] == pytest.approx(n_a ** 2 * t + g ** 2 * n_g ** 2 * t ** 3 / 3, rel=0.01)
    assert P[0, 0] == pytest.approx(n_a ** 2 * t ** 3 / 3 + g ** 2 * n_g ** 2 * t ** 5 / 20,
                                    rel=0.01)


def test_stationary_alignment_nulls_level_and_gyrocompass_rates():
    from fms_testbed.core.earth import earth_rate_enu
    from fms_testbed.sensors.sins.model import alignment_map
    from fms_testbed.sensors.sins.presets import load_imu

    imu = load_imu("STIM300")
    lat, c = 0.8, dcm_body_to_enu(0.02, 0.05, 1.2)
    g = -gravity_up(lat, 0.0)[0]
    F = build_F(lat, 0.0, np.zeros(3), c.T @ np.array([0, 0, g]), c.T @ earth_rate_enu(lat), c,
                imu.decay_rps, 0.0, 0.0)
    z = np.sqrt(imu.p0_var) * np.random.default_rng(0).standard_normal(33)
    x0 = alignment_map(lat, c, imu.decay_rps) @ z
    rate = F @ x0
    assert np.abs(rate[3:5]).max() < 1e-15                    # levelled: no horizontal δV'
    assert abs(rate[6]) < 1e-18                               # gyrocompassed: no east ε'
    assert np.abs((F @ z)[3:5]).max() > 1e-3                  # unaligned: biases drive δV


def test_aligned_stationary_ins_has_no_bias_schuler_bowl():
    from fms_testbed.sensors.sins.model import alignment_map
    F, c, g = _stationary_F()
    x0 = np.zeros(33)
    x0[9] = 1e-3 * G0_MPS2                                        # 1 mg east accelerometer bias
    x0 = alignment_map(math.radians(45.0), c, DECAY) @ x0
    _, x = _propagate(F, x0, 3600.0)
    assert np.abs(x[:, 0]).max() < 1.0                        # vs 12.7 km unaligned


def test_noise_mapped_through_G_gives_the_constant_diagonal_Q_of_eq_6_9():
    from fms_testbed.sensors.sins.model import noise_input_matrix
    from fms_testbed.sensors.sins.presets import load_imu

    q1 = load_imu("STIM300").q_psd                             # densities of η (eq. 6.9 order)
    G = noise_input_matrix(C)
    Q = G @ np.diag(q1) @ G.T
    assert np.allclose(Q, np.diag(q1), rtol=0, atol=1e-12 * q1.max())
