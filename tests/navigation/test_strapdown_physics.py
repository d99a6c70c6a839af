"""The strapdown INS against closed forms and the linear model: alignment residuals, the Schuler
period, and free-inertial error growth with the same sensor-error realisation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fms_testbed.core.earth import OMEGA_IE_RPS, normal_gravity_mps2, radii_m
from fms_testbed.navigation.inertial.bank import StrapdownBank
from fms_testbed.navigation.inertial.twin import linear_twin
from fms_testbed.navigation.ins_bank import derive_seeds
from fms_testbed.sensors.imu.kinematics import euler_to_quat, qrot
from fms_testbed.sensors.imu.synthesis import sample_of
from fms_testbed.sensors.sins.model import alignment_map, dcm_body_to_enu
from tests.navigation.strapdown_helpers import recorded_flight

BIASES = {"gyro": {"bias_turn_on_deg_per_h": 0.05, "scale_factor_ppm": 100,
                   "misalignment_mrad": 0.2},
          "accelerometer": {"bias_turn_on_ug": 300, "scale_factor_ppm": 300,
                            "misalignment_mrad": 0.5}}
"""Constant sensor errors only (no noise): the alignment residual is deterministic."""


def _start(bank, truth):
    bank.update(truth)
    return [bank.errors(i) for i in range(len(bank))]


def test_stationary_alignment_leaves_the_closed_form_residuals():
    """Levelling: ε_E = -δf^n_N/g, ε_N = δf^n_E/g; gyrocompassing: ε_U = -δω^n_E/(Ω cos φ) +
    tan φ ε_N (module docstring of alignment), the sensor errors resolved at rest; and the
    33-state model's alignment map gives the same residuals from the same sensor errors. Both
    are first order: what is left is second order, a relative max(|ε|, |δω^n|/(Ω cos φ)) (the
    heading error turns the tilt; the north gyro error scales the gyrocompass' reference)."""
    truth = recorded_flight(60.0)[0][0]
    bank = StrapdownBank([BIASES] * 8, derive_seeds(1, 8))
    lat = truth.lat_rad
    g = normal_gravity_mps2(lat, truth.alt_m)
    c_bn = dcm_body_to_enu(truth.roll_rad, truth.pitch_rad, truth.heading_rad)
    f_b = c_bn.T @ np.array([0.0, 0.0, g])
    w_b = c_bn.T @ np.array([0.0, OMEGA_IE_RPS * math.cos(lat), OMEGA_IE_RPS * math.sin(lat)])
    for e in _start(bank, truth):
        ba, bg = e[9:12], e[12:15]
        ka, kg, ma, mg = e[15:18], e[18:21], e[21:27], e[27:33]
        gam = lambda v, m: np.array([v[1] * m[0] + v[2] * m[1], v[0] * m[2] + v[2] * m[3],
                                     v[0] * m[4] + v[1] * m[5]])
        df = c_bn @ (ba + ka * f_b + gam(f_b, ma))       # ENU
        dw = c_bn @ (bg + kg * w_b + gam(w_b, mg))
        eps_n = df[0] / g
        want = np.array([-df[1] / g, eps_n, -dw[0] / (OMEGA_IE_RPS * math.cos(lat))
                         + math.tan(lat) * eps_n])
        second = max(np.max(np.abs(e[6:9])), np.max(np.abs(dw[:2])) / (OMEGA_IE_RPS
                                                                          * math.cos(lat)))
        tol = 2.0 * second * np.max(np.abs(want)) / math.cos(lat) ** 2 + 1e-9   # sec² φ: 2.1
        assert np.max(np.abs(e[6:9] - want)) < tol
        x = np.zeros(33)
        x[9:] = e[9:]
        assert np.max(np.abs((alignment_map(lat, c_bn, np.zeros(24)) @ x)[6:9] - e[6:9])) < tol
    assert abs(e[8]) > 1e-4                                # a visible heading residual


def test_alignment_residual_spread_is_bias_and_noise():
    """With noise: the heading residual's spread over 300 units is √(σ_bg² + N²/T)/(Ω cos φ) for
    a stationary alignment of T s (σ_bg the east gyro's bias, N its ARW)."""
    truth = recorded_flight(60.0)[0][0]
    spec = {"gyro": {"bias_turn_on_deg_per_h": 0.02, "arw_deg_per_sqrt_h": 0.01},
            "accelerometer": {"bias_turn_on_ug": 50, "vrw_mps_per_sqrt_h": 0.01}}
    T = 300.0
    bank = StrapdownBank([spec] * 300, derive_seeds(2, 300), alignment_s=T)
    E = np.array(_start(bank, truth))
    dph = math.radians(1.0) / 3600.0
    om = OMEGA_IE_RPS * math.cos(truth.lat_rad)
    want = math.hypot(0.02 * dph, 0.01 * math.radians(1.0) / 60.0 / math.sqrt(T)) / om
    # the heading residual also takes tan φ times the north tilt (about 1e-4 of this)
    assert np.std(E[:, 8]) == pytest.approx(want, rel=0.15)
    tilt = math.hypot(50e-6 * 9.80665, 0.01 / 60.0 / math.sqrt(T)) / 9.80665
    assert np.std(E[:, 6]) == pytest.approx(tilt, rel=0.15)


def test_gnss_heading_start_levels_on_the_accelerometers():
    """In-air start: the heading error has the GNSS heading's σ; the tilt is the accelerometer
    error over g (as at rest), plus what the trimmed flight's own acceleration a leaves (a/g:
    the levelling assumes none)."""
    from fms_testbed.navigation.inertial.alignment import expected_specific_force_ned
    truth = recorded_flight(60.0)[0][0]
    bank = StrapdownBank([BIASES] * 100, derive_seeds(3, 100), alignment="gnss_heading",
                         heading_sigma_deg=0.5)
    E = np.array(_start(bank, truth))
    assert np.std(np.degrees(E[:, 8])) == pytest.approx(0.5, rel=0.2)
    c_bn = dcm_body_to_enu(truth.roll_rad, truth.pitch_rad, truth.heading_rad)
    f_b = np.asarray(truth.f_body_mps2)
    v = truth.v_enu_mps
    f_exp = expected_specific_force_ned(truth.lat_rad, truth.alt_m, (v[1], v[0], -v[2]))
    a_n = c_bn @ f_b - np.array([f_exp[1], f_exp[0], -f_exp[2]])      # ENU
    g = -f_exp[2]
    gam = lambda v, m: np.array([v[1] * m[0] + v[2] * m[1], v[0] * m[2] + v[2] * m[3],
                                 v[0] * m[4] + v[1] * m[5]])
    for e in E:
        df = c_bn @ (e[9:12] + e[15:18] * f_b + gam(f_b, e[21:27]))
        want = np.array([-df[1] / g, df[0] / g])
        assert np.max(np.abs(e[6:8] - want)) < np.hypot(a_n[0], a_n[1]) / g + 2e-5


def test_free_inertial_oscillates_with_the_schuler_period():
    """At rest, an initial north velocity error of 0.1 m/s: the north position error crosses
    zero every π/ω_s, ω_s = √(g/R), R = √(M N) (84.4 min period); the vertical channel is held
    by the third-order baro loop on an exact baro."""
    truth = recorded_flight(60.0)[0][0]
    from dataclasses import replace
    rest = replace(truth, v_enu_mps=np.zeros(3), p_rps=0.0, q_rps=0.0, r_rps=0.0)
    bank = StrapdownBank([{}], [1])
    bank.update(rest)
    bank.correct(0, np.r_[0.0, 0.0, 0.0, 0.0, -0.1, 0.0, np.zeros(9)])
    frames = np.tile(sample_of(rest)[:6], (12, 1))
    t, north = [], []
    for k in range(1, int(2.2 * 3600 * 10)):
        bank.update(replace(rest, t_s=rest.t_s + 0.1 * k), frames)
        if k % 10 == 0:                                      # a baro reading a second
            bank.aid_vertical(rest.alt_m, 1.0)
        if k % 5 == 0:
            t.append(0.1 * k)
            north.append(bank.errors(0)[1])
    t, north = np.array(t), np.array(north)
    assert np.max(np.abs(north)) == pytest.approx(0.1 / 1.24e-3, rel=0.05)   # δv0/ω_s
    s = np.sign(north)
    k = np.nonzero(s[1:] != s[:-1])[0]
    zeros = t[k] - north[k] * (t[k + 1] - t[k]) / (north[k + 1] - north[k])
    rm, rn = radii_m(rest.lat_rad)
    w_s = math.sqrt(normal_gravity_mps2(rest.lat_rad, rest.alt_m) / math.sqrt(rm * rn))
    assert len(zeros) >= 3
    assert np.diff(zeros) == pytest.approx(math.pi / w_s, rel=2e-3)
    assert 2 * math.pi / w_s / 60 == pytest.approx(84.4, abs=0.2)


def test_free_vertical_channel_diverges_at_the_closed_form_rate_and_the_baro_loop_holds_it():
    """At rest, 1 m initial height error: free, h_err = cosh(ω_v t), ω_v = √(2γ/R) (e-folding
    570 s); with the third-order baro loop (τ 60 s) it decays."""
    truth = recorded_flight(60.0)[0][0]
    from dataclasses import replace
    rest = replace(truth, v_enu_mps=np.zeros(3), p_rps=0.0, q_rps=0.0, r_rps=0.0)
    frames = np.tile(sample_of(rest)[:6], (12, 1))
    free, aided = StrapdownBank([{}], [1]), StrapdownBank([{}], [1])
    for b in (free, aided):
        b.update(rest)
        b.correct(0, np.r_[0.0, 0.0, -1.0, np.zeros(12)])
    for k in range(1, 12001):
        r = replace(rest, t_s=rest.t_s + 0.1 * k)
        free.update(r, frames)
        aided.update(r, frames)
        if k % 10 == 0:
            aided.aid_vertical(rest.alt_m, 1.0)
    rm, rn = radii_m(rest.lat_rad)
    w_v = math.sqrt(2 * normal_gravity_mps2(rest.lat_rad, rest.alt_m) / math.sqrt(rm * rn))
    assert free.errors(0)[2] == pytest.approx(math.cosh(w_v * 1200.0), rel=0.02)
    assert 1 / w_v == pytest.approx(570, rel=0.01)
    assert abs(aided.errors(0)[2]) < 1e-3


def _same_realisation(preset, seed, calls):
    """Strapdown and the linear model with one deterministic realisation of ``preset``,
    along ``calls``: [(t, strapdown errors (33,), linear errors (33,))] every 60 s."""
    bank = StrapdownBank([preset], derive_seeds(seed, 1))
    bank.imu.make_deterministic()
    bank.update(calls[0][0])
    twin = linear_twin(bank, 0)
    twin.update(calls[0][0])
    out = []
    for k, (truth, frames) in enumerate(calls[1:], start=1):
        bank.update(truth, frames[:, :len(bank.frame_properties)])
        twin.update(truth)
        if k % 600 == 0:
            out.append((truth.t_s, bank.errors(0), twin.x.copy()))
    return out


@pytest.mark.parametrize("preset", ["HG9900", "HG1700", "STIM300", "ADIS16488"])
def test_linear_model_matches_the_strapdown_to_its_linearisation(preset):
    """Same trajectory (300 s of the JSBSim flight: turns, a climb), same constant sensor
    errors: the horizontal position errors differ by at most |ε| (the second-order term is
    ½|ε| relative, ε the largest attitude error) plus 1e-3 relative; and where |ε| is large (a
    MEMS unit's gyrocompass heading of tens of degrees) they really do differ."""
    calls = recorded_flight(300.0)
    for t, e, x in _same_realisation(preset, 5, calls):
        eps = np.max(np.abs(e[6:9]))
        h = np.hypot(e[0], e[1])
        d = np.hypot(e[0] - x[0], e[1] - x[1])
        assert d <= (eps + 1e-3) * h + 0.01, (t, d, h, eps)
        if eps > 0.3:
            assert d > 0.1 * eps * h
