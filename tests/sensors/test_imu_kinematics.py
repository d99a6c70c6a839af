"""The discrete strapdown step and its inverse: what an "exact" increment means, checked on a
synthetic trajectory, and the rotation helpers against scipy's."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from fms_testbed.core.earth import local_terms, normal_gravity_mps2, radii_m
from fms_testbed.sensors.imu.kinematics import (euler_to_quat, forward_step, inverse_step,
                                                new_row, qconj, qmul, qrot, quat_to_euler,
                                                quat_to_rotvec, rotvec_to_quat)

DT = 1.0 / 120.0


def manoeuvre(n: int, dt: float = DT):
    """A smooth trajectory with turns, climbs and roll oscillations: NED velocity (n+1, 3) and
    quaternions (n+1) — consistent with nothing in particular (the inverse does not care)."""
    t = np.arange(n + 1) * dt
    roll = 0.4 * np.sin(2 * np.pi * t / 40)
    pitch = 0.05 + 0.1 * np.sin(2 * np.pi * t / 65)
    yaw = 0.03 * t + 0.5 * np.sin(t / 7)
    v = np.stack([120 * np.cos(0.03 * t), 120 * np.sin(0.03 * t) + 5 * np.sin(t / 3),
                  -5 * np.sin(t / 20)], axis=1)
    return v, [euler_to_quat(a, b, c) for a, b, c in zip(roll, pitch, yaw)]


def test_mechanising_the_inverse_increments_reproduces_the_samples_to_round_off():
    v, q = manoeuvre(120 * 60)
    truth = new_row(math.radians(47), math.radians(8), 3000.0, v[0], q[0])
    nav = truth.copy()
    for k in range(1, len(q)):
        dth, dv = inverse_step(truth, tuple(v[k]), q[k], DT)
        forward_step(nav, dth, dv, DT)
        if k % 1200 == 0:
            rm, rn = radii_m(truth[0])
            assert abs(nav[0] - truth[0]) * rm < 1e-8
            assert abs(nav[1] - truth[1]) * rn < 1e-8
            assert abs(nav[2] - truth[2]) < 1e-8
            assert np.max(np.abs(nav[3:6] - v[k])) < 1e-10
            r = quat_to_rotvec(qmul(qconj(tuple(nav[6:10])), q[k]))
            assert max(abs(x) for x in r) < 1e-12


def test_increments_at_rest_are_earth_rate_and_the_reaction_to_gravity():
    """Two identical samples: Δθ = C_n^b ω_ie Δt, Δv = -C_n^b g^n Δt (to the step's precision)."""
    lat, h = math.radians(47.0), 1000.0
    q = euler_to_quat(0.1, -0.2, 2.0)
    row = new_row(lat, 0.0, h, (0.0, 0.0, 0.0), q)
    for _ in range(3):
        dth, dv = inverse_step(row, (0.0, 0.0, 0.0), q, DT)
    w_ie = qrot(qconj(q), (7.292115e-5 * math.cos(lat), 0.0, -7.292115e-5 * math.sin(lat)))
    g_b = qrot(qconj(q), (0.0, 0.0, -normal_gravity_mps2(lat, h)))
    assert np.allclose(np.array(dth) / DT, w_ie, rtol=0, atol=1e-13)
    assert np.allclose(np.array(dv) / DT, g_b, rtol=0, atol=1e-9)


def test_increments_approach_the_integrals_of_rate_and_specific_force():
    """A constant rotation rate in space and a constant velocity: Δθ/Δt tends to the body rate
    the attitude sequence implies (ω_nb + C_n^b ω_in)."""
    w = (0.2, -0.1, 0.3)                                   # body rate relative to n, rad/s
    lat, h = 0.8, 500.0
    q = euler_to_quat(0.0, 0.0, 0.0)
    row = new_row(lat, 0.0, h, (0.0, 0.0, 0.0), q)
    dq = rotvec_to_quat(tuple(x * DT for x in w))
    for _ in range(5):
        q = qmul(q, dq)
        dth, _ = inverse_step(row, (0.0, 0.0, 0.0), q, DT)
    w_ie = qrot(qconj(q), (7.292115e-5 * math.cos(lat), 0.0, -7.292115e-5 * math.sin(lat)))
    assert np.allclose(np.array(dth) / DT, np.array(w) + np.array(w_ie), atol=1e-9)


@pytest.mark.parametrize("seed", range(5))
def test_rotation_helpers_match_scipy(seed):
    rng = np.random.default_rng(seed)
    roll, pitch, yaw = rng.uniform(-3, 3), rng.uniform(-1.5, 1.5), rng.uniform(-3, 3)
    q = euler_to_quat(roll, pitch, yaw)
    ref = Rotation.from_euler("ZYX", [yaw, pitch, roll])      # C_b^n = Rz Ry Rx
    assert np.allclose(Rotation.from_quat([q[1], q[2], q[3], q[0]]).as_matrix(),
                       ref.as_matrix(), atol=1e-15)
    r, p, y = quat_to_euler(q)
    assert np.allclose([r, p], [roll, pitch], atol=1e-12)
    assert math.remainder(y - yaw, 2 * math.pi) == pytest.approx(0, abs=1e-12)
    v = tuple(rng.standard_normal(3))
    assert np.allclose(qrot(q, v), ref.apply(v), atol=1e-14)
    for scale in (1e-9, 1e-4, 0.049, 0.051, 0.5, 3.0):    # both sides of the series thresholds
        phi = rng.standard_normal(3)
        phi = tuple(scale * phi / np.linalg.norm(phi))
        qq = rotvec_to_quat(phi)
        ref_q = Rotation.from_rotvec(phi).as_quat()
        assert np.allclose([qq[1], qq[2], qq[3], qq[0]], ref_q, atol=1e-16)
        assert np.allclose(quat_to_rotvec(qq), phi, rtol=1e-14, atol=1e-20)


def test_local_terms_are_the_radii_and_gravity_of_the_earth_model():
    for lat in np.linspace(-1.55, 1.55, 13):
        for h in (0.0, 3000.0, 12000.0):
            s, c, im, inn, g = local_terms(lat, h)
            rm, rn = radii_m(lat)
            assert (s, c) == (math.sin(lat), math.cos(lat))
            assert 1.0 / im == pytest.approx(rm + h, rel=1e-15)
            assert 1.0 / inn == pytest.approx(rn + h, rel=1e-15)
            assert g == pytest.approx(normal_gravity_mps2(lat, h), rel=1e-15)
