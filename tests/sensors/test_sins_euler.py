"""Euler-angle error conversion (paper eq. 6.10) against a perturbed DCM."""

import math

import numpy as np
import scipy.linalg
from hypothesis import given, settings
from hypothesis import strategies as st

from fms_testbed.sensors.sins.euler import euler_errors_to_eps, euler_from_dcm_enu, eps_to_euler_errors
from fms_testbed.sensors.sins.model import dcm_body_to_enu


def _skew(v):
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def test_dcm_axes_follow_the_conventions():
    assert np.allclose(dcm_body_to_enu(0, 0, math.pi / 2) @ [1, 0, 0], [1, 0, 0])   # nose east
    assert np.allclose(dcm_body_to_enu(0, 0, 0) @ [0, 0, 1], [0, 0, -1])            # z down
    assert np.allclose(dcm_body_to_enu(0, 0.1, 0) @ [1, 0, 0], [0, math.cos(.1), math.sin(.1)])
    # right wing east at heading 0; rolling right puts it below the horizon
    assert np.allclose(dcm_body_to_enu(0.2, 0, 0) @ [0, 1, 0], [math.cos(.2), 0, -math.sin(.2)])


angles = st.tuples(st.floats(-1.2, 1.2), st.floats(-1.2, 1.2), st.floats(0, 2 * math.pi))
small = st.tuples(*[st.floats(-1e-5, 1e-5)] * 3)


@settings(max_examples=60, deadline=None)
@given(angles, small)
def test_eq_6_10_matches_a_perturbed_dcm(rph, eps):
    roll, pitch, head = rph
    eps = np.array(eps)
    c = dcm_body_to_enu(roll, pitch, head)
    c_star = scipy.linalg.expm(-_skew(eps)) @ c                  # C_B^N* = (I - ε×) C_B^N
    r2, p2, h2 = euler_from_dcm_enu(c_star)
    measured = np.array([r2 - roll, p2 - pitch, (h2 - head + math.pi) % (2 * math.pi) - math.pi])
    predicted = np.array(eps_to_euler_errors(*eps, pitch, head))
    assert np.allclose(predicted, measured, rtol=0, atol=1e-9 + 1e-4 * np.abs(eps).max())


@settings(max_examples=60, deadline=None)
@given(angles, small)
def test_conversion_round_trips(rph, eps):
    _, pitch, head = rph
    back = euler_errors_to_eps(*eps_to_euler_errors(*eps, pitch, head), pitch, head)
    assert np.allclose(back, eps, rtol=1e-9, atol=1e-18)


def test_conversion_is_vectorised():
    e = np.full(4, 1e-6)
    d = eps_to_euler_errors(e, 2 * e, 3 * e, np.zeros(4), np.linspace(0, 3, 4))
    assert all(np.shape(x) == (4,) for x in d)
