"""The truth-side IMU's sensor errors: parameters read from the presets, the sensor equations of
the 33-state model, noise densities, Gauss-Markov statistics, quantisation, faults."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numba import njit

from fms_testbed.core.units import DEG_RAD, DPH_RPS, G0_MPS2
from fms_testbed.navigation.ins_bank import _sensor_errors
from fms_testbed.sensors.imu.errors import (ImuErrorParams, ImuErrors, imu_error_params,
                                            layout_33, measure, measure_quantised, quantise)
from fms_testbed.sensors.sins.presets import load_imu, load_imu_spec


def test_stim300_parameters_are_the_preset_file_in_si():
    p = imu_error_params("STIM300")
    ug = 1e-6 * G0_MPS2
    assert np.allclose(p.on_sd, [750 * ug] * 3 + [0.0] * 3)
    assert np.allclose(p.gm_sd, [50 * ug] * 3 + [0.5 * DPH_RPS] * 3)
    assert np.all(p.gm_tau_s == 3600.0)
    assert np.allclose(p.sf_sd, [300e-6] * 3 + [500e-6] * 3)
    assert np.allclose(p.mis_sd, 1e-3)
    assert np.all(np.isinf(p.sf_tau_s)) and np.all(np.isinf(p.mis_tau_s))
    assert np.allclose(p.white_psd, [(0.06 / 60) ** 2] * 3 + [(0.15 * DEG_RAD / 60) ** 2] * 3)
    assert np.allclose(p.lsb, [2.0 ** -22] * 3 + [math.radians(2.0 ** -21)] * 3, rtol=1e-4)


def test_parameters_from_the_33_state_model_keep_its_variances():
    """A MEMS request has only the model arrays: same σ, decay and densities back out."""
    m = load_imu("HG1700")
    p = ImuErrorParams.from_model(m)
    spec = ImuErrorParams.from_spec(load_imu_spec("HG1700"))
    assert np.allclose(p.on_sd, spec.on_sd) and np.allclose(p.white_psd, spec.white_psd)
    mems = imu_error_params("STIM210+compensated")
    assert np.all(mems.lsb == 0.0) and np.all(np.isfinite(mems.white_psd))


def test_deterministic_errors_are_the_33_state_sensor_equations():
    """Bias, scale factor and the Γ misalignment on the increments equal the InsBank's error
    model (paper eq. 5.1-5.6) at the same state, rate and specific force."""
    rng = np.random.default_rng(3)
    e = rng.standard_normal(36) * 1e-3
    f = np.array([1.2, -0.4, -9.7])
    w = np.array([0.05, -0.02, 0.11])
    dt = 0.01
    th, v = measure(e, tuple(w * dt), tuple(f * dt), dt, np.zeros(6), np.zeros(6))
    mine = np.concatenate([(np.array(v) - f * dt) / dt, (np.array(th) - w * dt) / dt])
    x33 = np.zeros((1, 33))
    x33[0, 9:] = layout_33(e)
    ref = _sensor_errors(x33, np.zeros((1, 6)), f, w, np.zeros((1, 6)), np.zeros((1, 6)))[0]
    assert np.allclose(mine, ref, rtol=1e-12, atol=1e-18)


def test_white_noise_per_increment_has_the_declared_density():
    imu = ImuErrors([imu_error_params("STIM300")], [5])
    dt = 1.0 / 120.0
    sd = imu.white_sd(dt)[0]
    z = np.random.default_rng(0).standard_normal((20000, 6))
    e = np.zeros(36)
    out = np.array([np.concatenate(measure(e, (0.0,) * 3, (0.0,) * 3, dt, sd, zz)[::-1])
                    for zz in z[:4000]])
    arw = np.std(out[:, 3:]) / math.sqrt(dt)                   # rad/√s
    vrw = np.std(out[:, :3]) / math.sqrt(dt)
    assert arw == pytest.approx(0.15 * DEG_RAD / 60, rel=0.05)
    assert vrw == pytest.approx(0.06 / 60, rel=0.05)


def test_gauss_markov_and_random_walk_discretisation():
    """x ← a x + s N: stationary variance σ² for the Gauss-Markov part, q Δt growth for a
    random walk (unit-trap checks: σ√(2/τ) driving noise, √Δt steps)."""
    spec = {"gyro": {"bias_instability_deg_per_h": 2.0, "bias_correlation_time_s": 100.0,
                     "bias_rate_random_walk_deg_per_h_per_sqrt_h": 6.0}}
    p = imu_error_params(spec)
    a, s = p.step_coefficients(0.1)
    assert a[3] == pytest.approx(math.exp(-0.001))
    assert s[3] ** 2 / (1 - a[3] ** 2) == pytest.approx((2.0 * DPH_RPS) ** 2)
    assert a[9] == 1.0 and s[9] ** 2 == pytest.approx((6.0 * DPH_RPS / 60) ** 2 * 0.1)
    imu = ImuErrors([p] * 400, list(range(400)))
    A, S = imu.coefficients(1.0)
    rng = np.random.default_rng(1)
    for _ in range(300):
        imu.E[:, 6:] = A * imu.E[:, 6:] + S * rng.standard_normal(S.shape)
    assert np.std(imu.E[:, 9]) == pytest.approx(2.0 * DPH_RPS, rel=0.15)
    assert np.std(imu.E[:, 15]) == pytest.approx(6.0 * DPH_RPS / 60 * math.sqrt(300), rel=0.15)


@njit
def _quantised_sum(x, lsb):
    """(worst |Σ outputs - Σ inputs|, worst distance of an output from a multiple of lsb)."""
    res = 0.0
    total = 0.0
    worst = 0.0
    off = 0.0
    for k in range(x.size):
        y, res = quantise(x[k], lsb, res)
        off = max(off, abs(y / lsb - np.round(y / lsb)))
        total += y
        worst = max(worst, abs(total - x[:k + 1].sum()))
    return worst, off


def test_quantisation_is_an_integrating_output_whose_sum_never_drifts():
    x = np.random.default_rng(2).normal(3.3e-7, 2e-7, 5000)
    lsb = 2.0 ** -22
    worst, off = _quantised_sum(x, lsb)
    assert worst <= 0.5 * lsb * (1 + 1e-6) and off < 1e-9
    e = np.zeros(36)
    th, v = measure_quantised(e, (1e-3,) * 3, (0.08,) * 3, 0.01, np.zeros(6), np.zeros(6),
                              np.full(6, lsb), np.zeros(6))
    assert all(abs(c / lsb - round(c / lsb)) < 1e-9 for c in th + v)


def test_seeded_units_are_reproducible_and_independent():
    p = imu_error_params("STIM300")
    a, b = ImuErrors([p, p], [11, 12]), ImuErrors([p, p], [11, 99])
    assert np.array_equal(a.E[0], b.E[0]) and not np.array_equal(a.E[1], b.E[1])
    assert np.array_equal(a.rng_white[0].standard_normal(4), b.rng_white[0].standard_normal(4))


def test_fault_methods_change_the_truth_side_errors():
    p = imu_error_params("STIM300")
    imu = ImuErrors([p], [4])
    before = imu.values(0)
    imu.step_bias(0, "gyro", 2, 10 * DPH_RPS)
    imu.step_bias(0, "accel", 0, 1e-3)
    d = imu.values(0) - before
    assert d[5] == pytest.approx(10 * DPH_RPS) and d[0] == pytest.approx(1e-3)
    _, s0 = imu.coefficients(0.1)
    s0 = s0.copy()
    ex = imu.scale_gyro_drift(0, 3.0)
    assert np.allclose(ex, 2.0 * p.gm_sd[3:])
    _, s1 = imu.coefficients(0.1)
    assert np.allclose(s1[0, 3:6], 3.0 * s0[0, 3:6]) and np.allclose(s1[0, :3], s0[0, :3])
