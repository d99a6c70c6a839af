"""Kalman steps: the Joseph form with frozen gain rows, and the delayed-measurement correction
against its exact reference (the state augmented with a clone at the time of validity)."""

import numpy as np
import pytest

from fms_testbed.navigation.kalman import correct, correct_delayed, innovation, predict


def _random_spd(rng, n, scale=1.0):
    A = rng.standard_normal((n, n))
    return scale * (A @ A.T + n * np.eye(n))


def test_joseph_equals_the_optimal_short_form_and_frozen_states_keep_their_prediction():
    rng = np.random.default_rng(0)
    n, m = 6, 2
    x, P = rng.standard_normal(n), _random_spd(rng, n)
    H, R = rng.standard_normal((m, n)), _random_spd(rng, m, 0.1)
    z = rng.standard_normal(m)
    none = np.zeros(n, np.bool_)
    x1, P1, nu, S, nis = correct(x, P, z, H, R, none)
    K = P @ H.T @ np.linalg.inv(H @ P @ H.T + R)
    assert np.allclose(P1, (np.eye(n) - K @ H) @ P)
    assert np.allclose(x1, x + K @ (z - H @ x))
    assert nis == pytest.approx(nu @ np.linalg.solve(S, nu))
    frozen = np.zeros(n, np.bool_)
    frozen[[1, 4]] = True
    x2, P2, *_ = correct(x, P, z, H, R, frozen)
    assert x2[1] == x[1] and x2[4] == x[4]
    assert P2[1, 1] == pytest.approx(P[1, 1]) and P2[4, 4] == pytest.approx(P[4, 4])
    assert np.linalg.eigvalsh(P2).min() > 0
    # the sub-optimal estimate is never better than the optimal one
    assert np.trace(P2) >= np.trace(P1)


def test_delayed_correction_equals_the_augmented_clone_filter():
    rng = np.random.default_rng(1)
    n, m = 5, 3
    xm, Pm = rng.standard_normal(n), _random_spd(rng, n)          # at the time of validity
    phi = np.eye(n) + 0.1 * rng.standard_normal((n, n))
    Q = _random_spd(rng, n, 0.05)
    H, R = rng.standard_normal((m, n)), _random_spd(rng, m, 0.2)
    z = rng.standard_normal(m)
    x, P = predict(xm, Pm, phi, Q)                                   # the filter's time
    xd, Pd, nu, S, nis = correct_delayed(x, P, z, H, R, phi, Q, np.zeros(n, np.bool_))
    # reference: augmented state [x(t); x(t_m)] with cross-covariance Φ P_m
    Pa = np.block([[P, phi @ Pm], [(phi @ Pm).T, Pm]])
    xa = np.r_[x, xm]
    Ha = np.hstack([np.zeros((m, n)), H])
    xr, Prr, nur, Sr, nisr = correct(xa, Pa, z, Ha, R, np.zeros(2 * n, np.bool_))
    assert np.allclose(xd, xr[:n]) and np.allclose(Pd, Prr[:n, :n])
    assert np.allclose(nu, nur) and np.allclose(S, Sr) and nis == pytest.approx(nisr)


def test_delayed_correction_without_lag_is_the_joseph_form():
    rng = np.random.default_rng(2)
    n, m = 4, 2
    x, P = rng.standard_normal(n), _random_spd(rng, n)
    H, R, z = rng.standard_normal((m, n)), _random_spd(rng, m), rng.standard_normal(m)
    a = correct(x, P, z, H, R, np.zeros(n, np.bool_))
    b = correct_delayed(x, P, z, H, R, np.eye(n), np.zeros((n, n)), np.zeros(n, np.bool_))
    for u, v in zip(a, b):
        assert np.allclose(u, v)
    nu, S, nis = innovation(x, P, z, H, R)
    assert np.allclose(nu, a[2]) and nis == pytest.approx(a[4])
