"""Simulation x_k = Φ x + S N: semidefinite factorisation, Monte-Carlo statistics, seeding."""

import numpy as np
import pytest

from fms_testbed.sensors.sins.discretize import discretize
from fms_testbed.sensors.sins.simulate import IndefiniteCovarianceError, factor_psd, simulate_lti
from sins_helpers import flight_F


def test_factor_reproduces_a_singular_psd_matrix():
    F, q, _ = flight_F()
    _, qk = discretize(F, np.diag(q), 0.1)
    S = factor_psd(qk)
    assert S.shape[1] < qk.shape[0]                          # undriven constants: singular
    assert np.abs(S @ S.T - qk).max() <= 1e-12 * np.abs(qk).max()
    with pytest.raises(np.linalg.LinAlgError):               # why plain Cholesky is not enough
        np.linalg.cholesky(qk)


def test_factor_handles_zero_rows_and_rejects_indefinite():
    Q = np.array([[4.0, 0.0, 2.0], [0.0, 0.0, 0.0], [2.0, 0.0, 1.0]])   # rank 1, zero row
    S = factor_psd(Q)
    assert S.shape == (3, 1) and np.allclose(S @ S.T, Q)
    with pytest.raises(IndefiniteCovarianceError, match="indefinite"):
        factor_psd(np.array([[1.0, 2.0], [2.0, 1.0]]))
    with pytest.raises(IndefiniteCovarianceError):
        factor_psd(np.array([[0.0, 1e-3], [1e-3, 1.0]]))            # zero pivot, live column


def test_factor_tolerates_rounding_level_negative_pivot():
    v = np.array([1.0, 1.0 / 3.0, 2.0 / 3.0])
    Q = np.outer(v, v)                                       # rank 1; pivots 2, 3 ≈ ±1e-17
    S = factor_psd(Q)
    assert S.shape[1] == 1 and np.allclose(S @ S.T, Q, atol=1e-15)


def test_monte_carlo_variances_pass_z_test_for_every_state():
    F, q, imu = flight_F()
    n_real, n_steps, dt = 20_000, 100, 0.1
    x = simulate_lti(F, np.diag(q), dt, n_steps, imu.p0_var, n_real, seed=11)
    phi, qk = discretize(F, np.diag(q), dt)
    P = np.diag(imu.p0_var)
    for _ in range(n_steps):
        P = phi @ P @ phi.T + qk
    s2 = x[-1].var(axis=1, ddof=1)
    live = np.diag(P) > 0
    z = (s2[live] / np.diag(P)[live] - 1) / np.sqrt(2 / n_real)
    assert live.sum() >= 21
    assert np.all(np.abs(z) < 4), z


def test_simulation_is_reproducible_from_its_seed():
    F, q, imu = flight_F()
    a = simulate_lti(F, np.diag(q), 0.1, 20, imu.p0_var, 5, seed=3)
    b = simulate_lti(F, np.diag(q), 0.1, 20, imu.p0_var, 5, seed=3)
    c = simulate_lti(F, np.diag(q), 0.1, 20, imu.p0_var, 5, seed=4)
    assert np.array_equal(a, b) and not np.allclose(a, c)


def test_step_applies_the_discrete_input_matrix():
    from fms_testbed.sensors.sins.simulate import step

    F = np.array([[0.0, 1.0], [0.0, 0.0]])
    phi, qk, bk = discretize(F, np.zeros((2, 2)), 0.5, B=np.array([[0.0], [1.0]]))
    rng = np.random.default_rng(0)
    x = np.zeros(2)
    for _ in range(4):                                        # constant unit acceleration, 2 s
        x = step(x, phi, np.zeros((2, 0)), rng, bk=bk, u=np.array([1.0]))
    assert np.allclose(x, [0.5 * 2.0 ** 2, 2.0], rtol=1e-14)


from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402


@settings(max_examples=50, deadline=None)
@given(st.integers(0, 10_000), st.integers(1, 12), st.integers(0, 12))
def test_factor_recovers_rank_and_matrix_of_random_psd(seed, n, r):
    rng = np.random.default_rng(seed)
    r = min(r, n)
    # r well-conditioned rows (singular values >= ~0.3), the rest in their span, then mixed state
    # scales: the rank is decidable in double precision (independent Gaussian rows are, now and
    # then, within 1e-9 of the span of the rows before them, and the rank is then ambiguous)
    B0 = np.eye(r) + 0.1 * rng.normal(size=(r, r))
    B = np.vstack([B0, rng.normal(size=(n - r, r)) @ B0]) * 10.0 ** rng.uniform(-6, 3, size=(n, 1))
    Q = B @ B.T
    S = factor_psd(Q)
    assert S.shape[1] == r
    d = np.sqrt(np.diag(Q))
    d[d == 0] = 1.0
    assert np.abs((S @ S.T - Q) / np.outer(d, d)).max() <= 1e-8
