"""95 % horizontal radius of a 2-D Gaussian error ellipse (ANP/EPU from a covariance).

Pins issue 14's bug: the former 256-point trapezoid over the ellipse angle read elongated
ellipses short (−18 % at σ_min/σ_max = 0.01, −75 % at 0.001).
"""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.special import ndtri

from fms_testbed.core.errors import UserError
from fms_testbed.sensors.sins.analysis import horizontal_radius


def _rotated(s_major_m, ratio, angle_rad):
    """(p_ee, p_nn, p_en) m² of an ellipse with σ_max = s_major_m, σ_min = ratio·σ_max, rotated."""
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    R = np.array([[c, -s], [s, c]])
    P = R @ np.diag([s_major_m ** 2, (ratio * s_major_m) ** 2]) @ R.T
    return P[0, 0], P[1, 1], P[0, 1], P


@pytest.mark.parametrize("ratio", [1.0, 0.1, 0.01, 0.001])
def test_radius_inside_the_order_statistic_interval_of_a_seeded_monte_carlo(ratio):
    # distribution-free: the true 95 % quantile lies between the sorted radii at ranks
    # N p ± 4.5 √(N p (1-p)) with probability 1 - 7e-6
    p_ee, p_nn, p_en, P = _rotated(300.0, ratio, 0.7)
    n = 2_000_000
    rng = np.random.default_rng(14)
    xy = rng.standard_normal((n, 2)) @ np.linalg.cholesky(P).T
    rad = np.sort(np.hypot(xy[:, 0], xy[:, 1]))
    half = 4.5 * math.sqrt(n * 0.95 * 0.05)
    lo, hi = rad[int(n * 0.95 - half)], rad[int(n * 0.95 + half)]
    r = horizontal_radius(p_ee, p_nn, p_en)
    assert lo <= r <= hi, (ratio, lo, r, hi)
    # the interval is narrow enough to catch the old under-reading many times over
    assert (hi - lo) / r < 0.01


def test_limits_circular_and_one_dimensional_are_exact():
    for p in (0.5, 0.95, 0.999):
        assert horizontal_radius(4.0, 4.0, 0.0, p) == pytest.approx(
            2.0 * math.sqrt(-2.0 * math.log1p(-p)), rel=1e-12)
        assert horizontal_radius(9.0, 0.0, 0.0, p) == pytest.approx(3.0 * ndtri(0.5 + p / 2),
                                                                    rel=1e-14)
    assert horizontal_radius(0.0, 0.0, 0.0) == 0.0


@pytest.mark.parametrize("ratio", [1e-2, 1e-3, 1e-4])
def test_thin_ellipse_follows_the_second_order_expansion(ratio):
    # P(|x| ≤ r - y²/(2r)) with E[y²] = σ_min²: r ≈ z σ_max (1 + q²/(2 z²)), error O(q⁴)
    z = ndtri(0.975)
    r = horizontal_radius(1.0, ratio ** 2, 0.0)
    assert r == pytest.approx(z * (1.0 + ratio ** 2 / (2.0 * z * z)), rel=2.0 * ratio ** 4 + 1e-13)
    assert r > z    # strictly above the 1-D limit: the minor axis is resolved, not dropped


@settings(max_examples=60, deadline=None)
@given(s=st.floats(1e-3, 1e5), q=st.floats(1e-7, 1.0), ang=st.floats(0.0, math.pi),
       p=st.floats(0.05, 0.9999))
def test_rotation_and_scale_invariant_and_between_the_limits(s, q, ang, p):
    p_ee, p_nn, p_en, _ = _rotated(s, q, ang)
    r = horizontal_radius(p_ee, p_nn, p_en, p)
    assert r == pytest.approx(s * horizontal_radius(1.0, q * q, 0.0, p), rel=1e-9)
    assert ndtri(0.5 + p / 2) * s * (1 - 1e-9) <= r <= math.sqrt(-2 * math.log1p(-p)) * s * (1 + 1e-9)


def test_bad_probability_is_a_user_error():
    with pytest.raises(UserError, match="prob"):
        horizontal_radius(1.0, 1.0, 0.0, prob=1.0)
