"""The three compensation stages, each alone: temperature fit (and its refusal), switch-on offset,
slow-drift extractor (threshold + low-pass), and the stage list."""

import math

import numpy as np
import pytest
from scipy.stats import truncnorm

from fms_testbed.core.errors import UserError
from fms_testbed.sensors.mems.compensation import (CalibrationError, estimate_switch_on_offset,
                                                   extract_slow_drift,
                                                   fit_temperature_calibration, parse_stages)
from fms_testbed.sensors.mems.model import simulate_gyro, zero_signal_rps
from fms_testbed.sensors.mems.preset import gyro_model, load_mems
from fms_testbed.sensors.mems.temperature import ramp_profile, warmup_profile

DEG = math.pi / 180
QUIET = dict(arw_deg_per_sqrt_h=0.0, bias_instability_deg_per_h=0.0,
             rate_random_walk_deg_per_h_per_sqrt_h=0.0, resolution_deg_per_h=0.0,
             run_to_run_deg_per_s=0.0)


def _model(**gyro):
    spec = load_mems("STIM210")
    return gyro_model(spec.model_copy(update={"gyro": spec.gyro.model_copy(update=gyro)}))


def _cal_run(m, duration_s=14400.0):
    prof = ramp_profile(duration_s, -40, 85, 25, soak_s=600)
    return simulate_gyro(m, prof, duration_s, 1.0, np.random.default_rng(0))


def test_temperature_fit_recovers_the_polynomial_without_hysteresis():
    m = _model(**QUIET, hysteresis_deg_per_s=[0, 0, 0])
    rec = _cal_run(m)
    cal = fit_temperature_calibration(rec.temp_degC, rec.rate_rps, 1.0, 3, 30.0, 100.0)
    t = np.linspace(-39, 84, 50)
    # 1e-5 °/s: a 100-s window mean of the cubic is not the cubic at the window's mean temperature
    np.testing.assert_allclose(cal.zero_signal_rps(t), zero_signal_rps(m, t), atol=1e-5 * DEG)
    assert cal.residual_max_rps.max() < 1e-5 * DEG
    assert cal.range_degC[0] < -38 and cal.range_degC[1] > 83


def test_temperature_fit_residual_is_the_hysteresis_half_height():
    m = _model(**QUIET)
    rec = _cal_run(m)
    cal = fit_temperature_calibration(rec.temp_degC, rec.rate_rps, 1.0, 3, 30.0, 100.0)
    # the fit averages the heating and cooling branches (±H) except near the turning points and
    # the start, where one branch dominates and the cubic bends towards it: up to ~1.2 H
    ratio = cal.residual_max_rps / m.hysteresis_rps
    assert np.all((ratio > 1.0) & (ratio < 1.3)), ratio
    out = cal.apply(rec.rate_rps, rec.temp_degC)
    assert np.abs(out).max() < 1.3 * m.hysteresis_rps.max()


def test_temperature_fit_is_refused_over_a_small_swing():
    m = _model(**QUIET)
    prof = warmup_profile(7200, 20, 12, 900)
    rec = simulate_gyro(m, prof, 7200, 1.0, np.random.default_rng(0))
    with pytest.raises(CalibrationError, match=r"swings 1[12]\.\d degC, at least 30 degC"):
        fit_temperature_calibration(rec.temp_degC, rec.rate_rps, 1.0, 3, 30.0, 100.0)
    with pytest.raises(CalibrationError, match="zero-signal points"):
        fit_temperature_calibration(rec.temp_degC[:500], rec.rate_rps[:500], 1.0, 3, 1.0, 100.0)
    assert issubclass(CalibrationError, UserError)


def test_switch_on_offset_is_the_initial_static_mean():
    x = np.zeros((1000, 3))
    x[:, 1] = 0.01
    x[600:] += 5.0                                  # later motion does not enter
    np.testing.assert_allclose(estimate_switch_on_offset(x, 10.0, 60.0), [0, 0.01, 0])
    with pytest.raises(UserError, match="initial interval of 200 s"):
        estimate_switch_on_offset(x, 10.0, 200.0)


def test_slow_drift_removes_a_constant_below_the_threshold_up_to_the_truncation_bias():
    # N(μ, σ) samples, threshold c = 3σ: the extractor tracks E[X | |X| < c] (truncated normal)
    rng = np.random.default_rng(1)
    sigma, mu, c = 0.0167 * DEG, 0.005 * DEG, 0.05 * DEG
    x = mu + sigma * rng.standard_normal((720_000, 3))
    drift = extract_slow_drift(x, 100.0, c, 0.1)
    expected = truncnorm.mean((-c - mu) / sigma, (c - mu) / sigma, loc=mu, scale=sigma)
    residual = (x - drift)[1000:].mean(axis=0)
    np.testing.assert_allclose(residual, mu - expected, rtol=0.05)
    assert 0.02 < (mu - expected) / mu < 0.04      # ~2.7 % of the drift is left at 3σ


def test_slow_drift_passes_motion_above_the_threshold_and_holds_its_estimate():
    n = 6000                                        # 60 s at 100 Hz
    x = np.full((n, 3), 0.01 * DEG)
    x[3000:3500, 0] += 2.0 * DEG                    # a 2 °/s rotation for 5 s on x
    drift = extract_slow_drift(x, 100.0, 0.05 * DEG, 0.1)
    out = x - drift
    np.testing.assert_allclose(drift[3000:3500, 0], drift[2999, 0], rtol=1e-12)   # held
    assert drift[2999, 0] == pytest.approx(0.01 * DEG, rel=1e-6)
    np.testing.assert_allclose(out[3000:3500, 0], 2.0 * DEG, rtol=1e-6)           # passed
    big = np.full((100, 3), 1.0)                    # never below the threshold: nothing removed
    assert not extract_slow_drift(big, 100.0, 0.05 * DEG, 0.1).any()


def test_stage_list_is_canonical_and_checked():
    assert parse_stages("slow-drift, none,temperature") == ("none", "temperature", "slow-drift")
    with pytest.raises(UserError, match="unknown compensation stage 'kalman'"):
        parse_stages("none,kalman")
    with pytest.raises(UserError, match="no compensation stage"):
        parse_stages(" , ")
