"""The measurement plug-ins: H against a numerical Jacobian of z over the INS errors (lever arms
and all), and the filter's gate with its reset after sustained rejection."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fms_testbed.core.earth import radii_m
from fms_testbed.core.state import NavSolution
from fms_testbed.navigation.ins_filter import FilterTuning, InsGnssFilter
from fms_testbed.navigation.measurements import (Airspeed, BaroAltitude, GnssPosition,
                                                 GnssVelocity, skew)
from fms_testbed.sensors.gnss import GnssSpec
from fms_testbed.sensors.imu.kinematics import euler_to_quat, qmul, quat_to_euler, rotvec_to_quat

LAT, LON, ALT = math.radians(47.0), math.radians(8.0), 3000.0
V = np.array([120.0, 40.0, 3.0])
RPY = (0.3, 0.05, 1.1)
LEVER = np.array([2.0, -0.7, -1.5])
W = np.array([0.01, 0.02, 0.05])


def indicated(dx: np.ndarray) -> NavSolution:
    """The INS output with the error dx (δp ENU m, δV m/s, ε ENU rad; indicated - true):
    C_ind = (I - [ε×]) C_true, i.e. q_ind = q(ε_NED) ⊗ q_true as the feedback inverts it."""
    rm, rn = radii_m(LAT)
    q = euler_to_quat(*RPY)
    qi = qmul(rotvec_to_quat((-dx[7], -dx[6], dx[8])), q)
    r, p, h = quat_to_euler(qi)
    return NavSolution(0.0, LAT + dx[1] / (rm + ALT), LON + dx[0] / ((rn + ALT) * math.cos(LAT)),
                       ALT + dx[2], V + dx[3:6], r, p, h, {})


def _true_antenna() -> tuple[NavSolution, np.ndarray]:
    return indicated(np.zeros(9)), np.zeros(9)


@pytest.mark.parametrize("kind", ["pos", "vel", "baro", "airspeed"])
def test_h_is_the_jacobian_of_z_over_the_ins_errors(kind):
    truth = indicated(np.zeros(9))
    n = 22
    if kind == "pos":
        # a fix at the true antenna: z(0) = 0 when the INS is exact
        c = np.array(_c(truth))
        a = c @ LEVER
        rm, rn = radii_m(LAT)
        m = GnssPosition(0.0, LAT + a[1] / (rm + ALT), LON + a[0] / ((rn + ALT) * math.cos(LAT)),
                         ALT + a[2], np.ones(3), LEVER)
    elif kind == "vel":
        m = GnssVelocity(0.0, V + np.array(_c(truth)) @ np.cross(W, LEVER), np.ones(3), LEVER)
    elif kind == "baro":
        m = BaroAltitude(0.0, ALT, 1.0)
    else:
        m = Airspeed(0.0, float(np.linalg.norm(V - [5.0, -3.0, 0.0])), 1.0,
                     np.array([5.0, -3.0, 0.0]))
    z0, H, _ = m.matrices(truth, n, W)
    assert np.allclose(z0, 0.0, atol=1e-6)
    J = np.zeros((z0.size, 9))
    for j, h in enumerate([1.0] * 6 + [1e-5] * 3):
        d = np.zeros(9)
        d[j] = h
        J[:, j] = (m.matrices(indicated(d), n, W)[0] - m.matrices(indicated(-d), n, W)[0]) / (2 * h)
    assert np.allclose(H[:, :9], J, rtol=1e-4, atol=1e-6), (H[:, :9], J)


def _c(sol):
    from fms_testbed.navigation.measurements import c_bn_enu
    return c_bn_enu(sol)


def test_skew_is_the_cross_product():
    a, b = np.array([1.0, -2.0, 0.5]), np.array([0.3, 0.7, -1.1])
    assert np.allclose(skew(a) @ b, np.cross(a, b))


def _filter(reset_after: int) -> InsGnssFilter:
    f = InsGnssFilter(_imu(), GnssSpec(), None, FilterTuning(reset_after=reset_after))
    f.initialise(indicated(np.zeros(9)))
    f.P[:3, :3] += np.eye(3)
    return f


def _imu():
    from fms_testbed.sensors.sins.presets import load_imu
    return load_imu("STIM300")


def _fix_200m_north():
    rm, _ = radii_m(LAT)
    return GnssPosition(0.0, LAT + 200.0 / (rm + ALT), LON, ALT, np.full(3, 0.5), np.zeros(3))


def test_a_jump_is_rejected_then_reset_after_sustained_rejection():
    f = _filter(reset_after=4)
    sol = indicated(np.zeros(9))
    results = [f.use(_fix_200m_north(), sol) for _ in range(6)]
    assert [r.used for r in results] == [False] * 4 + [True, True]
    assert [r.reset for r in results] == [False] * 4 + [True, False]
    # after the reset the estimate follows the fix: the INS is 200 m south of it
    assert f.x[1] == pytest.approx(-200.0, abs=1.0)


def test_without_reset_the_jump_stays_rejected():
    f = _filter(reset_after=0)
    sol = indicated(np.zeros(9))
    assert not any(f.use(_fix_200m_north(), sol).used for _ in range(20))
    assert abs(f.x[1]) < 1e-9
