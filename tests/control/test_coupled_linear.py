"""Linear analysis (python-control): W(p) is diagonal and its poles sit where (T, ξ) put them."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fms_testbed.control import linear
from fms_testbed.control.coupled_law import CoupledLawParams

P = CoupledLawParams(T_V_s=6.0, xi_V=1.0, T_H_s=8.0, xi_H=0.8)


@settings(max_examples=30, deadline=None)
@given(T_V=st.floats(3.0, 20.0), xi_V=st.floats(0.5, 2.0), T_H=st.floats(3.0, 25.0),
       xi_H=st.floats(0.5, 2.0), V0=st.floats(40.0, 260.0), measured=st.booleans())
def test_closed_loop_without_lags_is_decoupled_with_the_designed_poles(T_V, xi_V, T_H, xi_H, V0,
                                                                     measured):
    p = CoupledLawParams(T_V_s=T_V, xi_V=xi_V, T_H_s=T_H, xi_H=xi_H)
    sys = linear.closed_loop(p, V0, use_measured_nx=measured)
    r = linear.decoupling_report(sys, p)
    assert r.off_V_from_H <= 1e-9
    assert r.off_H_from_V <= 1e-9
    assert r.dc_gain == pytest.approx(np.eye(2), abs=1e-9)
    assert r.pole_error <= 1e-6 * max(1.0, np.abs(r.desired_poles).max()) + 1e-6
    assert len(r.poles) == 4


def test_diagonal_entries_are_the_desired_second_order_systems():
    sys = linear.closed_loop(P, 111.1)
    w = np.logspace(-2, 1, 50)
    W = linear.frequency_response(sys, w)
    s = 1j * w
    want_v = 1.0 / (P.T_V_s ** 2 * s ** 2 + 2 * P.xi_V * P.T_V_s * s + 1)
    want_h = 1.0 / (P.T_H_s ** 2 * s ** 2 + 2 * P.xi_H * P.T_H_s * s + 1)
    assert np.max(np.abs(W[0, 0] - want_v)) < 1e-9
    assert np.max(np.abs(W[1, 1] - want_h)) < 1e-9


def test_unequal_inner_loop_lags_break_the_decoupling_measurably():
    ideal = linear.decoupling_report(linear.closed_loop(P, 111.1), P)
    lagged = linear.decoupling_report(linear.closed_loop(P, 111.1, 0.3, 0.9), P)
    assert ideal.off_V_from_H < 1e-12
    assert lagged.off_V_from_H > 1e-4
    assert lagged.pole_error > 1e-3
    t = np.linspace(0, 120, 1201)
    _, sh = linear.step_responses(linear.closed_loop(P, 111.1, 0.3, 0.9), t, 0.0, 100.0)
    assert 0.05 < np.abs(sh[0]).max() * 3.6 < 2.0         # km/h of speed error in a 100 m step


def test_measured_nx_in_the_damping_term_keeps_equal_lags_decoupled():
    same = linear.decoupling_report(linear.closed_loop(P, 111.1, 0.5, 0.5, True), P)
    cmd = linear.decoupling_report(linear.closed_loop(P, 111.1, 0.5, 0.5, False), P)
    assert same.off_V_from_H < 1e-9
    assert cmd.off_V_from_H > 1e-4


def test_siso_entry_of_w_is_a_transfer_function():
    tf = linear.siso_tf(linear.closed_loop(P, 111.1), "V", "V_cmd")
    assert float(np.real(tf(0.0))) == pytest.approx(1.0, abs=1e-9)
