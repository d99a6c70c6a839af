"""The compiled per-step code of navigation/fdi.py (SensorComparator's ring sums and z test, the
pair flags, channel_sigmas, vote on cached flags) against plain numpy restatements of the
documented rules, written here independently of the module."""

import math

import numpy as np
import pytest

from fms_testbed.navigation.fdi import (PAIRS, FdiTuning, SensorComparator, TwoStageFdi,
                                        channel_mask, channel_sigmas, pair_flags)

DT = 0.1
Q = np.r_[[(0.06 / 60) ** 2] * 3, [(math.radians(0.15) / 60) ** 2] * 3]


def _step_test(hist_d, hist_u, var, sf, ns, nl):
    """Seed 001's sensor-level step test on stored histories, by slicing: Δ = mean of the last
    ns samples - mean of the nl - ns before, σ_Δ² = var (1/N_s + 1/N_r) + σ_k² |Δu|²."""
    nr = nl - ns
    delta = hist_d[-ns:].mean(axis=0) - hist_d[-nl:-ns].mean(axis=0)          # (pairs, 3)
    du = hist_u[-ns:].mean(axis=0) - hist_u[-nl:-ns].mean(axis=0)             # (3,)
    return delta / np.sqrt(var * (1.0 / ns + 1.0 / nr) + sf * np.sum(du ** 2))


@pytest.mark.parametrize("n_units", [3, 2])
def test_sensor_comparator_equals_the_window_means_of_its_history(n_units):
    rng = np.random.default_rng(11 + n_units)
    tun = FdiTuning(accel_window_s=0.5, gyro_window_s=2.0, reference_s=8.0, k_sensor=4.0)
    q = np.tile(Q, (n_units, 1)) * rng.uniform(0.5, 2.0, (n_units, 6))
    sf = np.abs(rng.normal(2e-6, 5e-7, (n_units, 2)))
    comp = SensorComparator(n_units, q, DT, sf, tun)
    pairs = [p for p in PAIRS if p[1] < n_units]
    ia, ib = [p[0] for p in pairs], [p[1] for p in pairs]
    var = (q[ia] + q[ib]) / DT
    sfp = np.repeat(sf[ia] + sf[ib], 3, axis=1)
    windows = [(max(1, round(w / DT)), max(1, round(w / DT)) + round(tun.reference_s / DT))
               for w in (tun.accel_window_s, tun.gyro_window_s)]
    offs = rng.normal(0, 1e-3, (n_units, 6))
    hist_d, hist_f, hist_w = [], [], []
    flagged = tested = 0
    for k in range(3000):
        turn = (k // 300) % 2                                      # manoeuvres change f and w
        f = np.array([0.0, 0.0, -9.80665 * (1.3 if turn else 1.0)]) + rng.normal(0, 0.05, 3)
        w = np.array([0.0, 0.0, 0.05 * turn]) + rng.normal(0, 1e-3, 3)
        errs = offs + np.sqrt(q / DT) * rng.standard_normal((n_units, 6))
        if k >= 1000:
            errs[0, 1] += 2e-2                                     # an accelerometer step, unit 1
        if k >= 2000:
            errs[1, 4] += 5e-4                                     # a gyro step on unit 2
        got = comp.update(k * DT, errs, f, tuple(w))
        hist_d.append(errs[ia] - errs[ib])
        hist_f.append(f)
        hist_w.append(w)
        want = np.zeros(len(pairs), bool)
        for g, (ns, nl) in enumerate(windows):
            cols = slice(3 * g, 3 * g + 3)
            if len(hist_d) < nl:
                continue
            z = _step_test(np.array(hist_d[-nl:])[:, :, cols], np.array((hist_f, hist_w)[g][-nl:]),
                           var[:, cols], sfp[:, cols], ns, nl)
            np.testing.assert_allclose(comp.last_z[:, cols], z, rtol=1e-12, atol=1e-12)
            assert not (np.abs(np.abs(z) - tun.k_sensor) < 1e-9).any()    # no tie to decide
            want |= (np.abs(z) > tun.k_sensor).any(axis=1)
            tested += 1
        expect = dict(zip(pairs, want.astype(int).tolist()))
        assert got == tuple(expect.get(p, 0) for p in PAIRS)
        assert all(type(v) is int for v in got)
        flagged += int(want.any())
    assert tested > 4000 and flagged > 20          # the step test ran, and the step was seen


def _flags_restated(y, sig, k, mask):
    """ν_ij = 1 when some channel in ``mask`` of y_i - y_j (heading wrapped to ±π) exceeds
    k √(σ_i² + σ_j²)."""
    out = []
    for a, b in PAIRS:
        if b >= len(y):
            out.append(0)
            continue
        d = np.asarray(y[a], float) - np.asarray(y[b], float)
        d[8] = math.remainder(d[8], 2 * math.pi)
        thr = k * np.sqrt(np.asarray(sig[a]) ** 2 + np.asarray(sig[b]) ** 2)
        out.append(int((np.abs(d) > thr)[mask].any()))
    return tuple(out)


def _comparison_inputs(rng, n=3, T=600):
    """Comparison vectors near the heading wrap with jumps on one unit, their σ, a mask that
    toggles the vertical channels."""
    sig = np.abs(1.0 + 0.2 * rng.standard_normal((T, n, 9)))
    sig[:, :, 6:] *= 1e-3
    y = rng.standard_normal((T, n, 9)) * sig * 2.0
    y[:, :, 8] = np.remainder(y[:, :, 8] + math.pi, 2 * math.pi) - math.pi + math.pi * 0.999
    jump = rng.random((T, 9)) < 0.05
    y[:, n - 1] += jump * 8.0 * sig[:, n - 1]
    frozen = (np.arange(T) // 50) % 2 == 1
    return y, sig, frozen


def test_pair_flags_and_vote_on_cached_flags_equal_the_restated_rule():
    rng = np.random.default_rng(7)
    y, sig, frozen = _comparison_inputs(rng)
    tun = FdiTuning(persist_s=0.3, isolate_s=1e9)          # persistence, never a timed exclusion
    fdi = TwoStageFdi(3, tun)
    votes = []
    for k in range(len(y)):
        mask = channel_mask(bool(frozen[k]))
        yl, sl = list(y[k]), list(sig[k])
        want = _flags_restated(yl, sl, tun.k_pair, mask)
        assert tuple(pair_flags(y[k], sig[k], tun.k_pair, mask).tolist()) == want
        fdi.update(round(k * DT, 6), yl, sl, (0, 0, 0), mask)
        assert fdi.flags == want
        cached = fdi.vote(yl, sl, mask, flags=fdi.flags)
        assert cached == fdi.vote(yl, sl, mask) == fdi.vote(yl, sl, mask, flags=np.array(want))
        bad = {(1, 1, 0): 0, (1, 0, 1): 1, (0, 1, 1): 2}.get(want)
        assert cached == [i for i in range(3) if i != bad]
        votes.append(len(cached))
    assert 3 in votes and 2 in votes                      # the vote dropped a unit, and not always


def test_pair_flags_of_two_units_and_of_non_array_inputs():
    rng = np.random.default_rng(8)
    y, sig, frozen = _comparison_inputs(rng, n=2, T=200)
    fdi2 = TwoStageFdi(2)
    seen = 0
    for k in range(len(y)):
        mask = channel_mask(bool(frozen[k]))
        want = _flags_restated(list(y[k]), list(sig[k]), 6.0, mask)
        assert tuple(pair_flags(y[k].tolist(), sig[k].tolist(), 6.0, mask.tolist())) == want
        fdi2.pairwise(k * DT, list(y[k]), list(sig[k]), mask)
        assert fdi2.flags == want
        seen += want[0]
    assert seen > 0


def test_pair_flags_keeps_math_remainders_errors_and_nan():
    y = np.zeros((3, 9))
    sig = np.ones((3, 9))
    y[0, 8] = math.inf
    with pytest.raises(ValueError):
        pair_flags(y, sig, 6.0)
    with pytest.raises(ValueError):
        TwoStageFdi(3).update(0.0, list(y), list(sig))
    y[0, 8] = math.nan
    y[1, 0] = math.nan
    assert pair_flags(y, sig, 6.0).tolist() == [0, 0, 0]


def test_channel_sigmas_equal_the_documented_formula():
    """σ = √max(P_ii, 0); tilt σ² = max(P_φ, P_θ) + var_a n² + var_g (φ² + θ²); heading σ² =
    P_ψ + var_g (φ² + θ²) — on random covariances, with zero and negative diagonal entries."""
    rng = np.random.default_rng(9)
    for k in range(300):
        P = np.diag(np.abs(rng.normal(1.0, 0.3, 21)) * 10.0 ** rng.uniform(-9, 1, 21))
        if k % 10 == 0:
            P[k % 9, k % 9] = -1e-12 if k % 20 else 0.0
        var_a, var_g = (0.0, 0.0) if k % 7 == 0 else tuple(np.abs(rng.normal(2e-6, 5e-7, 2)))
        roll, pitch, n = rng.normal(0, 0.5), rng.normal(0, 0.1), rng.uniform(0.8, 2.0)
        p = np.maximum(np.diag(P)[:9], 0.0)
        p[6] = p[7] = max(p[6], p[7])
        rot2 = var_g * (roll ** 2 + pitch ** 2)
        p[6:8] += var_a * n ** 2 + rot2
        p[8] += rot2
        got = channel_sigmas(P, (var_a, var_g), roll, pitch, n)
        assert got.shape == (9,) and got.dtype == np.float64
        np.testing.assert_allclose(got, np.sqrt(p), rtol=1e-14, atol=0.0)
        big = np.zeros((42, 42))
        big[::2, ::2] = P                                          # strided and Fortran order
        for Pv in (big[::2, ::2], np.asfortranarray(P)):
            np.testing.assert_array_equal(channel_sigmas(Pv, (var_a, var_g), roll, pitch, n), got)
