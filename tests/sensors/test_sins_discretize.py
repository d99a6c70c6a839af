"""Discretisation (Φ, Q_k, B_k): Picard vs Van Loan and closed forms (note sins-error-model.md)."""

import math

import numpy as np
import pytest

from fms_testbed.sensors.sins.discretize import (DiscretisationError, discretize, discretize_sins,
                                         picard_order_used)
from fms_testbed.sensors.sins.simulate import IndefiniteCovarianceError, factor_psd
from sins_helpers import flight_F


def rel(a, b):
    return np.abs(a - b).max() / np.abs(b).max()


@pytest.mark.parametrize("dt", [0.01, 0.05, 0.1])
def test_adaptive_picard_matches_van_loan_to_1e12_on_33_state_model(dt):
    F, q, _ = flight_F()
    Q = np.diag(q)
    phi, qk = discretize(F, Q, dt)
    phi_v, qk_v = discretize(F, Q, dt, method="vanloan")
    assert rel(phi, phi_v) <= 1e-12
    assert rel(qk, qk_v) <= 1e-12
    d, dv = np.diag(qk), np.diag(qk_v)
    assert np.all(np.abs(d - dv) <= 1e-12 * dv + 1e-300)   # every variance, relative


def test_structured_picard_equals_dense_picard():
    F, q, _ = flight_F()
    phi, qk = discretize(F, np.diag(q), 0.1)
    phi_s, qk_s = discretize_sins(F, q, 0.1)
    assert rel(phi_s, phi) <= 1e-14 and rel(qk_s, qk) <= 1e-14


def test_picard_needs_few_terms_at_10_hz():
    F, q, _ = flight_F()
    assert 4 <= picard_order_used(F, np.diag(q), 0.1) <= 10


def test_lyapunov_residual_vanishes():
    # d/dt Q_k = F Q_k + Q_k Fᵀ + Q = Φ Q Φᵀ
    F, q, _ = flight_F()
    Q = np.diag(q)
    phi, qk = discretize(F, Q, 0.1)
    res = F @ qk + qk @ F.T + Q - phi @ Q @ phi.T
    assert np.abs(res).max() <= 1e-10 * np.abs(Q).max()


def test_semigroup_property():
    F, q, _ = flight_F()
    Q = np.diag(q)
    phi, qk = discretize(F, Q, 0.1)
    ph, qh = discretize(F, Q, 0.05)
    assert rel(ph @ ph, phi) <= 1e-13
    assert rel(ph @ qh @ ph.T + qh, qk) <= 1e-12


@pytest.mark.parametrize("method", ["picard", "vanloan", "trapezoid"])
def test_random_walk_closed_form(method):
    phi, qk = discretize(np.zeros((1, 1)), np.array([[2.5]]), 0.1, method=method)
    assert phi[0, 0] == pytest.approx(1.0) and qk[0, 0] == pytest.approx(0.25, rel=1e-14)


@pytest.mark.parametrize("method", ["picard", "vanloan"])
def test_gauss_markov_closed_form(method):
    sigma, tau, dt = 0.3, 50.0, 0.1
    phi, qk = discretize(np.array([[-1 / tau]]), np.array([[2 * sigma ** 2 / tau]]), dt, method)
    assert phi[0, 0] == pytest.approx(math.exp(-dt / tau), rel=1e-14)
    assert qk[0, 0] == pytest.approx(sigma ** 2 * (1 - math.exp(-2 * dt / tau)), rel=1e-12)


@pytest.mark.parametrize("method", ["picard", "vanloan", "trapezoid"])
def test_double_integrator_closed_form_and_input_matrix(method):
    q, dt = 3.0, 0.1
    F = np.array([[0.0, 1.0], [0.0, 0.0]])
    phi, qk, bk = discretize(F, np.diag([0.0, q]), dt, method=method, B=np.array([[0.0], [1.0]]))
    assert np.allclose(phi, [[1, dt], [0, 1]], rtol=0, atol=1e-15)
    assert np.allclose(bk[:, 0], [dt * dt / 2, dt], rtol=1e-13, atol=0)
    exact = q * np.array([[dt ** 3 / 3, dt ** 2 / 2], [dt ** 2 / 2, dt]])
    if method == "trapezoid":     # eq. 3.1 is second order: exact up to the Δt³ term
        assert abs(qk[0, 0] - exact[0, 0]) == pytest.approx(q * dt ** 3 / 6, rel=1e-9)
    else:
        assert np.allclose(qk, exact, rtol=1e-13, atol=0)


@pytest.mark.parametrize("method", ["picard", "vanloan"])
def test_brown_hwang_oscillator(method):
    # y'' + y = 2u, unit white u, Δt = 0.1 (Brown & Hwang)
    F = np.array([[0.0, 1.0], [-1.0, 0.0]])
    phi, qk = discretize(F, np.diag([0.0, 4.0]), 0.1, method=method)
    assert np.allclose(phi, [[0.99500417, 0.09983342], [-0.09983342, 0.99500417]], atol=5e-9)
    assert np.allclose(qk, [[0.00133067, 0.01993342], [0.01993342, 0.39866933]], atol=5e-9)


def test_trapezoid_is_second_order_accurate():
    F, q, _ = flight_F()
    Q = np.diag(q)
    errs = []
    for dt in (0.1, 0.05):
        phi_t, _ = discretize(F, Q, dt, method="trapezoid")
        phi_v, _ = discretize(F, Q, dt, method="vanloan")
        errs.append(np.abs(phi_t - phi_v).max())
    assert 6.0 < errs[0] / errs[1] < 10.0          # Φ error ∝ Δt³


def test_picard_refuses_when_dt_over_tau_is_large():
    F = np.array([[-1 / 0.5]])                      # τ = 0.5 s, Δt/τ = 0.2
    with pytest.raises(DiscretisationError, match="vanloan"):
        discretize(F, np.array([[1.0]]), 0.1)
    phi, _ = discretize(F, np.array([[1.0]]), 0.1, method="vanloan")
    assert phi[0, 0] == pytest.approx(math.exp(-0.2))


def test_low_fixed_orders_give_singular_then_indefinite_Qk():
    F, q, _ = flight_F()
    Q = np.diag(q)
    _, q1 = discretize(F, Q, 0.1, order=1)
    assert factor_psd(q1).shape[1] < np.count_nonzero(np.diag(factor_psd(discretize(F, Q, 0.1)[1])))
    _, q2 = discretize(F, Q, 0.1, order=2)
    with pytest.raises(IndefiniteCovarianceError):
        factor_psd(q2)


def test_equal_fixed_order_8_matches_van_loan():
    F, q, _ = flight_F()
    phi, qk = discretize(F, np.diag(q), 0.1, order=8)
    phi_v, qk_v = discretize(F, np.diag(q), 0.1, method="vanloan")
    assert rel(phi, phi_v) <= 1e-12 and rel(qk, qk_v) <= 1e-12


def test_bad_arguments_raise_user_errors():
    with pytest.raises(DiscretisationError, match="unknown method"):
        discretize(np.zeros((1, 1)), np.zeros((1, 1)), 0.1, method="euler")
    with pytest.raises(DiscretisationError, match="dt"):
        discretize(np.zeros((1, 1)), np.zeros((1, 1)), 0.0)


def test_discretize_is_exported_as_a_package_function():
    import fms_testbed.sensors.sins as sins
    phi, qk = sins.discretize(np.zeros((1, 1)), np.eye(1), 0.1)
    assert phi[0, 0] == 1.0 and qk[0, 0] == pytest.approx(0.1)


from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 10_000), st.integers(2, 8), st.floats(0.001, 0.1))
def test_picard_matches_van_loan_for_random_models(seed, n, dt):
    rng = np.random.default_rng(seed)
    F = rng.normal(size=(n, n)) * 0.5
    F -= np.diag(np.diag(F))                                 # keep Δt·|F_ii| inside the range
    F += np.diag(-rng.uniform(0, 0.9, n))
    G = rng.normal(size=(n, n))
    Q = G @ G.T
    phi, qk = discretize(F, Q, dt)
    phi_v, qk_v = discretize(F, Q, dt, method="vanloan")
    assert rel(phi, phi_v) <= 1e-12 and rel(qk, qk_v) <= 1e-12
