"""Allan-variance identification recovers the noise terms the records were generated with; the
streaming octave Allan variance equals allantools' oadev."""

import allantools
import numpy as np

from fms_testbed.sensors.mems.allan import BlockReducer, OctaveAllan, averaging_times_s, fit_allan
from fms_testbed.sensors.mems.model import simulate_gyro
from fms_testbed.sensors.mems.preset import gyro_model, load_mems
from fms_testbed.sensors.mems.temperature import constant_profile

RECORD_S = 20 * 3600.0      # Sensonor's bias-instability test: 20 h at ambient (~25 °C)
RATE_HZ = 10.0


def test_fit_recovers_arw_and_bias_instability_over_ten_seeds():
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
    # every seed and axis, not only the mean: the fitted floor of one 20-h axis scatters by
    # about 4.5 % (1 sigma), so 30 draws stay within 15 % and their mean within 3 %
    assert arw_err.max() < 0.10, arw_err.max()
    assert bi_err.max() < 0.15, bi_err.max()
    bi_mean = np.mean(bi) / spec.gyro.bias_instability_deg_per_h - 1
    assert abs(bi_mean) < 0.03, bi_mean


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


def _record(n, rate_hz, seed):
    m = gyro_model(load_mems("STIM210"))
    return simulate_gyro(m, constant_profile(n / rate_hz, 25), n / rate_hz, rate_hz,
                         np.random.default_rng(seed)).rate_rps


def test_octave_allan_equals_allantools_oadev_at_the_octave_taus():
    y = _record(120_000, 10.0, 5)
    ref = None
    for parts in (1, 9, 250):
        oa = OctaveAllan(y.shape[0], 10.0, offsets=10 ** 9)     # every offset at every τ
        for c in np.array_split(y, parts):
            oa.update(c)
        tau, adev = oa.result()
        if ref is None:
            ref = adev
        np.testing.assert_array_equal(adev, ref)                # chunking changes no bit
    np.testing.assert_allclose(tau * 10.0, 2.0 ** np.arange(14))     # 1 .. 8192 <= n / 10
    other = np.array([allantools.oadev(y[:, a], rate=10.0, data_type="freq", taus=tau)[1]
                      for a in range(3)]).T
    np.testing.assert_allclose(ref, other, rtol=1e-9)


def test_strided_octave_allan_keeps_oadev_where_it_overlaps_fully_and_its_scatter_beyond():
    y = _record(400_000, 10.0, 6)
    oa = OctaveAllan(y.shape[0], 10.0, offsets=32)
    for c in np.array_split(y, 17):
        oa.update(c)
    tau, adev = oa.result()
    other = np.array([allantools.oadev(y[:, a], rate=10.0, data_type="freq", taus=tau)[1]
                      for a in range(3)]).T
    full = oa.stride == 1
    np.testing.assert_allclose(adev[full], other[full], rtol=1e-9)
    # every 2^(j-5)-th start beyond: the terms are a subset of oadev's, the same within their
    # scatter (over 3 axes, tau up to a tenth of the record: at least ~20 independent terms)
    rel = adev[~full] / other[~full] - 1
    assert rel.size > 0 and np.abs(rel).max() < 0.1, rel
    fit_s, fit_a = oa.fit(), fit_allan(y, 10.0)
    np.testing.assert_allclose(fit_s.arw_deg_per_sqrt_h, fit_a.arw_deg_per_sqrt_h, rtol=0.02)


def test_block_reducer_matches_whole_array_means_whatever_the_chunks():
    x = np.random.default_rng(2).standard_normal((10_007, 3))
    whole = x[:10_000].reshape(100, 100, 3).mean(axis=1)
    for sizes in ([10_007], [1, 99, 100, 5000, 4807], [33] * 303 + [8]):
        r = BlockReducer(100, 3)
        got = np.vstack([r.means(x[i:i + k]) for i, k in
                         zip(np.cumsum([0, *sizes[:-1]]), sizes)])
        np.testing.assert_array_equal(got, whole)
        np.testing.assert_array_equal(r.rest_sum(), x[10_000:].sum(axis=0))
