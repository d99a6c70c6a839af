"""Allan-variance identification recovers the noise terms the records were generated with."""

import numpy as np

from fms_testbed.sensors.mems.allan import averaging_times_s, fit_allan
from fms_testbed.sensors.mems.model import simulate_gyro
from fms_testbed.sensors.mems.preset import gyro_model, load_mems
from fms_testbed.sensors.mems.temperature import constant_profile

RECORD_S = 20 * 3600.0      # Sensonor's bias-instability test: 20 h at ambient (~25 °C)
RATE_HZ = 10.0


def test_fit_recovers_arw_and_bias_instability_within_10_percent_over_ten_seeds():
    spec = load_mems("STIM210")
    m = gyro_model(spec)
    prof = constant_profile(RECORD_S, spec.temperature.constant_degC)
    arw, bi = [], []
    for seed in range(10):
        rec = simulate_gyro(m, prof, RECORD_S, RATE_HZ, np.random.default_rng(seed))
        fit = fit_allan(rec.rate_rps, RATE_HZ)
        arw.append(fit.arw_deg_per_sqrt_h)
        bi.append(fit.bias_instability_deg_per_h)
    arw_err = np.abs(np.array(arw) / spec.gyro.arw_deg_per_sqrt_h - 1)
    bi_err = np.abs(np.array(bi) / spec.gyro.bias_instability_deg_per_h - 1)
    # every seed and axis, not only the mean
    assert arw_err.max() < 0.10, arw_err.max()
    assert bi_err.max() < 0.10, bi_err.max()


def test_fitted_model_reproduces_the_allan_curve_it_was_fitted_to():
    spec = load_mems("STIM210")
    rec = simulate_gyro(gyro_model(spec), constant_profile(7200, 25), 7200, 100,
                        np.random.default_rng(0))
    fit = fit_allan(rec.rate_rps, 100.0)
    assert fit.tau_s[0] == 0.01 and fit.tau_s[-1] <= 720.0
    rel = fit.model_adev_rps(fit.tau_s) / fit.adev_rps - 1
    assert np.abs(rel[fit.tau_s < 10]).max() < 0.03        # ARW region: tight
    assert np.abs(rel).max() < 0.35                         # long τ: few intervals in 2 h
    d = fit.to_dict()
    assert len(d["arw_deg_per_sqrt_h"]) == 3 and d["record_s"] == 7200.0


def test_averaging_times_are_whole_sample_multiples_up_to_a_tenth_of_the_record():
    t = averaging_times_s(100_000, 10.0, 30)
    m = t * 10.0
    np.testing.assert_allclose(m, np.round(m))
    assert t[0] == 0.1 and t[-1] == 1000.0 and np.all(np.diff(t) > 0)
