"""MEMS gyro error model: each term has its documented size, the seed fixes every number."""

import math

import allantools
import numpy as np
import pytest

from scipy.signal import sosfilt, sosfreqz

from fms_testbed.sensors.mems.model import (GyroStream, flicker_filter, simulate_gyro,
                                            zero_signal_rps)
from fms_testbed.sensors.mems.preset import gyro_model, load_mems
from fms_testbed.sensors.mems.temperature import constant_profile, warmup_profile

DEG = math.pi / 180


def _model(**gyro):
    spec = load_mems("STIM210")
    return gyro_model(spec.model_copy(update={"gyro": spec.gyro.model_copy(update=gyro)}))


QUIET = dict(arw_deg_per_sqrt_h=0.0, bias_instability_deg_per_h=0.0,
             rate_random_walk_deg_per_h_per_sqrt_h=0.0, resolution_deg_per_h=0.0,
             run_to_run_deg_per_s=0.0)


def test_same_seed_same_numbers_other_seed_other_numbers():
    m = gyro_model(load_mems("STIM210"))
    prof = warmup_profile(120, 20, 12, 900)
    a = simulate_gyro(m, prof, 120, 100, np.random.default_rng(5))
    b = simulate_gyro(m, prof, 120, 100, np.random.default_rng(5))
    c = simulate_gyro(m, prof, 120, 100, np.random.default_rng(6))
    np.testing.assert_array_equal(a.rate_rps, b.rate_rps)
    assert not np.array_equal(a.rate_rps, c.rate_rps)
    assert a.rate_rps.shape == (12000, 3) and a.t_s[-1] == pytest.approx(119.99)


def test_noise_free_output_is_the_temperature_polynomial_plus_hysteresis():
    m = _model(**QUIET)
    prof = warmup_profile(600, 20, 12, 100)
    rec = simulate_gyro(m, prof, 600, 10, np.random.default_rng(0))
    # heating by more than 2 w: after the first w the sensor is on the heating branch (h = +1)
    hot = rec.temp_degC > 20 + m.hysteresis_width_degC + 0.1
    expect = zero_signal_rps(m, rec.temp_degC) + m.hysteresis_rps
    np.testing.assert_allclose(rec.rate_rps[hot], expect[hot], rtol=0, atol=1e-15)
    assert rec.rate_rps[0] == pytest.approx(zero_signal_rps(m, [20.0])[0])   # relaxed at start


def test_white_noise_per_sample_sigma_is_arw_times_root_rate():
    m = _model(**{**QUIET, "arw_deg_per_sqrt_h": 0.1}, hysteresis_deg_per_s=[0, 0, 0])
    rec = simulate_gyro(m, constant_profile(600, 25), 600, 100, np.random.default_rng(1))
    s = rec.rate_rps.std(axis=0)
    expect = 0.1 * DEG / 60 * math.sqrt(100)          # N √f_s, rad/s
    n = rec.rate_rps.shape[0]
    z = (s ** 2 / expect ** 2 - 1) / math.sqrt(2 / n)
    assert np.all(np.abs(z) < 4), z


def test_run_to_run_offset_has_the_preset_sigma_over_switch_ons():
    m = _model(**{**QUIET, "run_to_run_deg_per_s": 0.0025})
    rng = np.random.default_rng(2)
    prof = constant_profile(1, 25)
    d = np.array([simulate_gyro(m, prof, 1, 10, rng).switch_on_offset_rps for _ in range(400)])
    z = (d.var(axis=0) / (0.0025 * DEG) ** 2 - 1) / math.sqrt(2 / d.shape[0])
    assert np.all(np.abs(z) < 4), z


def test_flicker_filter_psd_follows_h_over_f_within_1_db_in_its_band():
    floor = 0.5 * DEG / 3600
    h = floor ** 2 / (2 * math.log(2))                  # one-sided PSD h/f, Allan floor
    sos = flicker_filter(floor, 1e-6, 25.0, 100.0)
    f = np.logspace(-5, 1, 300)                         # a decade inside each band edge
    _, resp = sosfreqz(sos, worN=f, fs=100.0)
    psd = 2 * 0.01 * np.abs(resp) ** 2                  # unit white noise at 100 Hz
    db = 10 * np.log10(psd * f / h)
    assert np.abs(db).max() < 1.0, np.abs(db).max()
    _, low = sosfreqz(sos, worN=[1e-8], fs=100.0)       # DC blocked below the band
    assert 2 * 0.01 * abs(low[0]) ** 2 * 1e-8 / h < 1e-3


def test_flicker_noise_has_a_flat_allan_floor_at_the_bias_instability():
    floor = 0.5 * DEG / 3600
    n, rate = 400_000, 10.0
    sos = flicker_filter(floor, 0.1 * rate / n, 0.25 * rate, rate)
    taus = np.array([1.0, 10.0, 100.0, 1000.0])
    adev = np.array([allantools.oadev(sosfilt(sos, np.random.default_rng(s).standard_normal(n)),
                                      rate=rate, data_type="freq", taus=taus)[1]
                     for s in range(4)]).mean(axis=0)
    np.testing.assert_allclose(adev / floor, 1.0, atol=0.08)


def test_a_run_generated_in_chunks_equals_the_whole_run_bit_for_bit():
    m = gyro_model(load_mems("STIM210"))
    prof = warmup_profile(900, 20, 12, 300)
    whole = simulate_gyro(m, prof, 900, 100, np.random.default_rng(8))
    for sizes in ([90_000], [1, 4999, 30_000, 55_000], [7] * 20 + [89_860]):
        s = GyroStream(m, prof, 900, 100, np.random.default_rng(8))
        parts = [s.next(k) for k in sizes]
        assert s.i == s.n == 90_000
        np.testing.assert_array_equal(np.vstack([p[2] for p in parts]), whole.rate_rps)
        np.testing.assert_array_equal(np.concatenate([p[1] for p in parts]), whole.temp_degC)
        np.testing.assert_array_equal(s.switch_on_offset_rps, whole.switch_on_offset_rps)


def test_output_is_quantised_to_the_resolution():
    m = gyro_model(load_mems("STIM210"))
    rec = simulate_gyro(m, constant_profile(10, 25), 10, 100, np.random.default_rng(4))
    q = rec.rate_rps / m.resolution_rps
    np.testing.assert_allclose(q, np.round(q), atol=1e-6)


def test_profile_shorter_than_the_run_is_refused():
    m = gyro_model(load_mems("STIM210"))
    with pytest.raises(ValueError, match="covers 10.0 s"):
        simulate_gyro(m, constant_profile(10, 25), 20, 10, np.random.default_rng(0))
