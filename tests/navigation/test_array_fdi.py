"""The array identification (navigation/array_fdi.py) takes, realisation by realisation, the
decisions of TwoStageFdi / SensorComparator (navigation/fdi.py) on the same inputs."""

import numpy as np

from fms_testbed.navigation.array_fdi import ArrayFdi, ArraySensorComparator
from fms_testbed.navigation.fdi import FdiTuning, SensorComparator, TwoStageFdi


def _inputs(R=24, T=400, seed=3):
    """Comparison vectors with a fault growing on one unit in some realisations, random NIS with
    outliers, sparse sensor-level flags."""
    rng = np.random.default_rng(seed)
    sig = np.abs(1.0 + 0.1 * rng.standard_normal((R, 3, 9)))
    y = rng.standard_normal((T, R, 3, 9)) * sig
    unit = rng.integers(0, 3, R)
    start = rng.integers(50, 300, R)
    rate = rng.choice([0.0, 0.02, 0.1, 0.5], R)
    for r in range(R):
        ramp = np.clip(np.arange(T) - start[r], 0, None) * rate[r]
        y[:, r, unit[r], rng.integers(0, 9)] += ramp
    nis = rng.chisquare(3, (T, R, 3)) * np.where(rng.random((T, R, 3)) < 0.02, 30.0, 1.0)
    nu_s = (rng.random((T, R, 3)) < 0.01).astype(int)
    return y, sig, nis, nu_s


def test_array_fdi_matches_two_stage_fdi():
    y, sig, nis, nu_s = _inputs()
    T, R = y.shape[:2]
    tun = FdiTuning(persist_s=0.5, isolate_s=2.0, window_s=3.0, alpha=1e-3)
    arr = ArrayFdi(R, tun)
    ref = [TwoStageFdi(3, tun) for _ in range(R)]
    used_arr, used_ref = [], []
    for k in range(T):
        t = round(0.1 * k, 10)
        if k % 10 == 0:
            arr.add_innovation(t, nis[k], 3)
            for r in range(R):
                for i in range(3):
                    ref[r].add_innovation(i, t, float(nis[k, r, i]), 3)
        arr.update(t, y[k], sig, nu_s[k])
        for r in range(R):
            ref[r].update(t, list(y[k, r]), list(sig[r]), tuple(nu_s[k, r]))
        used_arr.append(arr.used.copy())
        used_ref.append(np.array([f.state.used for f in ref]))
    used_arr, used_ref = np.array(used_arr), np.array(used_ref)
    assert (~used_ref).any(), "the inputs must make the reference exclude something"
    assert (used_ref.all(axis=2)).any(), "and keep some realisations whole"
    np.testing.assert_array_equal(used_arr, used_ref)


def test_array_sensor_comparator_matches_sensor_comparator():
    rng = np.random.default_rng(5)
    R, T, dt = 6, 900, 0.1
    q = np.abs(rng.normal(1e-6, 1e-7, (3, 6)))
    sf = np.abs(rng.normal(1e-8, 1e-9, (3, 2)))
    tun = FdiTuning(k_sensor=4.0)
    arr = ArraySensorComparator(R, q, dt, sf, tun)
    ref = [SensorComparator(3, q, dt, sf, tun) for _ in range(R)]
    errs = rng.standard_normal((T, R, 3, 6)) * np.sqrt(q / dt)
    errs[700:, 2, 1, 4] += 5e-3                          # a gyro step on unit 2, realisation 2
    seen = 0
    for k in range(T):
        f = np.array([0.1, 0.0, -9.8]) + 0.5 * rng.standard_normal(3)
        w = 0.01 * rng.standard_normal(3)
        got = arr.update(errs[k], f, w)
        want = np.array([ref[r].update(k * dt, errs[k, r], f, w) for r in range(R)])
        np.testing.assert_array_equal(got, want)
        seen += int(want.any())
    assert seen > 0
