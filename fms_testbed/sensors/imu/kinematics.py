"""The discrete strapdown step that defines what an IMU increment means, and its exact inverse.

Frames and conventions: navigation frame n = local-level NED at the IMU (geodetic latitude φ,
longitude λ, ellipsoidal height h, WGS-84 from :mod:`fms_testbed.core.earth`); body frame b = IMU
axes x forward, y right, z down; attitude as the unit quaternion q = q_b^n (scalar first, v_n =
q ⊗ v_b ⊗ q*), Euler angles roll φ, pitch θ, heading ψ with C_b^n = R_z(ψ) R_y(θ) R_x(φ).
An increment over [t_{k-1}, t_k] is Δθ_k = ∫ ω_ib^b dt (rad) and Δv_k = ∫ f^b dt (m/s), f the
specific force at the IMU.

One step k of length Δt (Savage 1998; Shin 2001; the KF-GINS ``insmech`` layout), given the
state at k-1 and the previous increments Δθ', Δv' (zero at the first step):

* the step point: the midpoint x_m = x_{k-1} + ½ r (x_{k-1} - x_{k-2}) (latitude, height,
  velocity) extrapolated from the two previous states (r = Δt_k/Δt_{k-1}; at the first step
  x_m = x_{k-1}); the radii M, N, the normal gravity γ and the Earth rate are evaluated there
  once per step (:func:`fms_testbed.core.earth.local_terms`);
* velocity::

      Δv_sf^b = Δv + ½ Δθ × Δv + (Δθ' × Δv + Δv' × Δθ)/12        (rotation + two-sample sculling)
      ζ_v = (ω_ie^n + ω_en^n(v_m)) Δt
      v_k = v_{k-1} + (I - ½ [ζ_v×]) C_b^n(k-1) Δv_sf^b + (g^n - (2 ω_ie^n + ω_en^n) × v_m) Δt

* position, trapezoidal in the velocity: φ_k = φ_{k-1} + ½(v_N,k-1 + v_N,k) Δt/(M + h_m),
  λ_k = λ_{k-1} + ½(v_E,k-1 + v_E,k) Δt/((N + h_m) cos φ_m), h_k = h_{k-1} - ½(v_D,k-1 + v_D,k) Δt;
* attitude, with the transport rate at the step's mean velocity v̄ = ½(v_{k-1} + v_k)::

      φ_b = Δθ + Δθ' × Δθ / 12                                      (two-sample coning)
      ζ = (ω_ie^n + ω_en^n(v̄)) Δt
      q_k = q(-ζ) ⊗ q_{k-1} ⊗ q(φ_b)

g^n = (0, 0, γ(φ, h)) is the normal gravity of WGS-84 (:func:`fms_testbed.core.earth.normal_gravity_mps2`).

Every term but Δθ, Δv is a function of the old state and the new velocity, so the step
inverts exactly
(:func:`inverse_step`): from the sampled attitude q_k the body rotation φ_b = rotvec(q_{k-1}* ⊗
q(ζ) ⊗ q_k) and Δθ = (I + [Δθ'/12 ×])⁻¹ φ_b; from the sampled velocity Δv_sf^b, then Δv =
(I + [(½Δθ + Δθ'/12)×])⁻¹ (Δv_sf^b - Δv' × Δθ/12), with (I + [c×])⁻¹ b = (b - c × b + c (c·b)) /
(1 + |c|²). "Exact" therefore means: mechanising the error-free increments with
:func:`forward_step` reproduces the sampled velocity and attitude to round-off, and the position
to round-off where the samples' positions are the trapezoidal integral of their velocities (the
synthesis integrates its own positions that way; JSBSim's positions agree with it to 1e-5 m over
10 min, see the docs).

State rows (numpy float64, :data:`NS` columns) carry everything a step needs::

    0 lat rad, 1 lon rad, 2 h m, 3:6 v NED m/s, 6:10 q_b^n, 10:13 Δθ' rad, 13:16 Δv' m/s,
    16 lat_{k-2} rad, 17 h_{k-2} m, 18:21 v_{k-2} m/s, 21 Δt_{k-1} s (0: no history yet)
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from fms_testbed.core.earth import OMEGA_IE_RPS, local_terms

NS = 22
"""Columns of a state row (see the module docstring)."""
LAT, LON, H, VEL, QUAT, DTH, DV, LAT2, H2, VEL2, DT2 = (0, 1, 2, 3, 6, 10, 13, 16, 17, 18, 21)


# --- 3-vectors and quaternions as tuples (no allocation in compiled loops) -----------------------


@njit(cache=True, inline="always")
def cross3(a, b):
    """a × b of two 3-tuples."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@njit(cache=True, inline="always")
def axpy3(k, a, b):
    """k a + b of two 3-tuples and a float."""
    return (k * a[0] + b[0], k * a[1] + b[1], k * a[2] + b[2])


@njit(cache=True, inline="always")
def dot3(a, b):
    """a · b of two 3-tuples."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True, inline="always")
def solve_i_plus_skew(c, b):
    """x with (I + [c×]) x = b: x = (b - c × b + c (c·b)) / (1 + |c|²)."""
    cb = cross3(c, b)
    k = dot3(c, b)
    d = 1.0 + dot3(c, c)
    return ((b[0] - cb[0] + c[0] * k) / d, (b[1] - cb[1] + c[1] * k) / d,
            (b[2] - cb[2] + c[2] * k) / d)


@njit(cache=True, inline="always")
def qmul(p, q):
    """Hamilton product p ⊗ q of two scalar-first quaternions (4-tuples)."""
    return (p[0] * q[0] - p[1] * q[1] - p[2] * q[2] - p[3] * q[3],
            p[0] * q[1] + p[1] * q[0] + p[2] * q[3] - p[3] * q[2],
            p[0] * q[2] - p[1] * q[3] + p[2] * q[0] + p[3] * q[1],
            p[0] * q[3] + p[1] * q[2] - p[2] * q[1] + p[3] * q[0])


@njit(cache=True, inline="always")
def qconj(q):
    """Conjugate q* (the inverse rotation of a unit quaternion)."""
    return (q[0], -q[1], -q[2], -q[3])


@njit(cache=True, inline="always")
def qrot(q, v):
    """q ⊗ v ⊗ q* for a unit quaternion q and a 3-tuple v: v + 2w (u × v) + 2 u × (u × v)."""
    u = (q[1], q[2], q[3])
    t = cross3(u, v)
    t = (2.0 * t[0], 2.0 * t[1], 2.0 * t[2])
    s = cross3(u, t)
    return (v[0] + q[0] * t[0] + s[0], v[1] + q[0] * t[1] + s[1], v[2] + q[0] * t[2] + s[2])


@njit(cache=True, inline="always")
def qnormalize(q):
    """q / |q| for |q| within 1e-6 of 1: one Newton step for 1/|q|, k = (3 - |q|²)/2 (error
    (|q|² - 1)²: round-off)."""
    k = 0.5 * (3.0 - (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]))
    return (q[0] * k, q[1] * k, q[2] * k, q[3] * k)


@njit(cache=True, inline="always")
def rotvec_to_quat(phi):
    """Quaternion of the rotation vector φ (rad): (cos ½|φ|, sin(½|φ|) φ/|φ|); below |φ| =
    0.05 rad by their series to |φ|⁶ (truncation < 4e-18)."""
    n2 = dot3(phi, phi)
    if n2 < 2.5e-3:
        c = 1.0 - n2 / 8.0 * (1.0 - n2 / 48.0 * (1.0 - n2 / 120.0))
        k = 0.5 - n2 / 48.0 * (1.0 - n2 / 80.0 * (1.0 - n2 / 168.0))
    else:
        n = math.sqrt(n2)
        c = math.cos(0.5 * n)
        k = math.sin(0.5 * n) / n
    return (c, k * phi[0], k * phi[1], k * phi[2])


@njit(cache=True, inline="always")
def quat_to_rotvec(q):
    """Rotation vector (rad) of a unit quaternion, |φ| ≤ π: φ = 2 atan2(|u|, w) u/|u| with w ≥ 0."""
    w, x, y, z = q
    if w < 0.0:
        w, x, y, z = -w, -x, -y, -z
    s2 = x * x + y * y + z * z
    if s2 < 6.25e-4 * w * w:                  # atan(t)/t series, t = s/w < 0.025 (to t^10)
        t2 = s2 / (w * w)
        k = 2.0 / w * (1.0 - t2 * (1.0 / 3.0 - t2 * (0.2 - t2 * (1.0 / 7.0 - t2 / 9.0))))
    else:
        s = math.sqrt(s2)
        k = 2.0 * math.atan2(s, w) / s
    return (k * x, k * y, k * z)


@njit(cache=True)
def euler_to_quat(roll_rad, pitch_rad, heading_rad):
    """q_b^n of Euler angles (ZYX: C_b^n = R_z(ψ) R_y(θ) R_x(φ)), rad."""
    cr, sr = math.cos(0.5 * roll_rad), math.sin(0.5 * roll_rad)
    cp, sp = math.cos(0.5 * pitch_rad), math.sin(0.5 * pitch_rad)
    cy, sy = math.cos(0.5 * heading_rad), math.sin(0.5 * heading_rad)
    return (cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy)


@njit(cache=True)
def quat_to_euler(q):
    """(roll, pitch, heading) rad of q_b^n; heading in [0, 2π), pitch clipped to ±π/2."""
    w, x, y, z = q
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    s = 2.0 * (w * y - z * x)
    pitch = math.asin(min(1.0, max(-1.0, s)))
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return roll, pitch, yaw % (2.0 * math.pi)


# --- the navigation-frame terms of one step ------------------------------------------------------


@njit(cache=True, inline="always")
def step_point(row, dt):
    """The step's navigation point, extrapolated to its middle from the row's two last states
    (module docstring): (φ_m rad, v_m NED m/s, sin φ_m, cos φ_m, 1/(M+h_m), 1/(N+h_m) 1/m, γ m/s²)."""
    lat, h = row[LAT], row[H]
    v = (row[VEL], row[VEL + 1], row[VEL + 2])
    if row[DT2] > 0.0:
        r = 0.5 * dt / row[DT2]
        lat = lat + r * (lat - row[LAT2])
        h = h + r * (h - row[H2])
        v = (v[0] + r * (v[0] - row[VEL2]), v[1] + r * (v[1] - row[VEL2 + 1]),
             v[2] + r * (v[2] - row[VEL2 + 2]))
    s, c, im, inn, g = local_terms(lat, h)
    return lat, v, s, c, im, inn, g


@njit(cache=True, inline="always")
def _rates(v, s, c, im, inn):
    """(ω_ie^n, ω_en^n) rad/s at velocity v (NED m/s) with the point's Earth terms."""
    wie = (OMEGA_IE_RPS * c, 0.0, -OMEGA_IE_RPS * s)
    wen = (v[1] * inn, -v[0] * im, -v[1] * s / c * inn)
    return wie, wen


@njit(cache=True, inline="always")
def velocity_terms(v, s, c, im, inn, g, dt):
    """(ζ_v rad, Δv_gc m/s): the frame rotation (ω_ie + ω_en) Δt and the gravity/Coriolis
    increment (g^n - (2 ω_ie + ω_en) × v) Δt at the step point's velocity ``v``."""
    wie, wen = _rates(v, s, c, im, inn)
    cor = cross3((2.0 * wie[0] + wen[0], 2.0 * wie[1] + wen[1], 2.0 * wie[2] + wen[2]), v)
    zeta = ((wie[0] + wen[0]) * dt, (wie[1] + wen[1]) * dt, (wie[2] + wen[2]) * dt)
    return zeta, (-cor[0] * dt, -cor[1] * dt, (g - cor[2]) * dt)


@njit(cache=True, inline="always")
def position_step(lat, lon, h, v0, v1, c, im, inn, dt):
    """(φ_k rad, λ_k rad, h_k m): trapezoidal position update from the velocities v0 (k-1) and
    v1 (k) (NED m/s) with the step point's cos φ, 1/(M+h), 1/(N+h) (1/m); Δt in s."""
    return (lat + 0.5 * (v0[0] + v1[0]) * dt * im,
            lon + 0.5 * (v0[1] + v1[1]) * dt * inn / c, h - 0.5 * (v0[2] + v1[2]) * dt)


@njit(cache=True, inline="always")
def _shift_history(row, dt):
    """Keep the state at k-1 as the extrapolation basis of the next step."""
    row[LAT2] = row[LAT]
    row[H2] = row[H]
    for j in range(3):
        row[VEL2 + j] = row[VEL + j]
    row[DT2] = dt


@njit(cache=True, inline="always")
def _attitude_rotation(v0, v1, s, c, im, inn, dt):
    """ζ (rad) of the attitude update: (ω_ie + ω_en) Δt at the step's mean velocity."""
    vm = (0.5 * (v0[0] + v1[0]), 0.5 * (v0[1] + v1[1]), 0.5 * (v0[2] + v1[2]))
    wie, wen = _rates(vm, s, c, im, inn)
    return ((wie[0] + wen[0]) * dt, (wie[1] + wen[1]) * dt, (wie[2] + wen[2]) * dt)


@njit(cache=True, inline="always")
def _store(row, lat1, lon1, h1, v1, q1, dth, dv, dt):
    _shift_history(row, dt)
    row[LAT] = lat1
    row[LON] = lon1
    row[H] = h1
    for j in range(3):
        row[VEL + j] = v1[j]
        row[DTH + j] = dth[j]
        row[DV + j] = dv[j]
    for j in range(4):
        row[QUAT + j] = q1[j]


@njit(cache=True, inline="always")
def forward_step(row, dth, dv, dt):
    """Mechanise one increment pair in place (module docstring): Δθ (rad) and Δv (m/s) as
    3-tuples over Δt (s); the row then holds the state at k and these increments as Δθ', Δv'."""
    dth0 = (row[DTH], row[DTH + 1], row[DTH + 2])
    dv0 = (row[DV], row[DV + 1], row[DV + 2])
    scul = axpy3(1.0 / 12.0, axpy3(1.0, cross3(dth0, dv), cross3(dv0, dth)),
                 axpy3(0.5, cross3(dth, dv), dv))
    q0 = (row[QUAT], row[QUAT + 1], row[QUAT + 2], row[QUAT + 3])
    _, vm, s, c, im, inn, g = step_point(row, dt)
    zeta_v, dv_gc = velocity_terms(vm, s, c, im, inn, g, dt)
    dvn = qrot(q0, scul)
    dvn = axpy3(-0.5, cross3(zeta_v, dvn), dvn)
    v0 = (row[VEL], row[VEL + 1], row[VEL + 2])
    v1 = (v0[0] + dvn[0] + dv_gc[0], v0[1] + dvn[1] + dv_gc[1], v0[2] + dvn[2] + dv_gc[2])
    lat1, lon1, h1 = position_step(row[LAT], row[LON], row[H], v0, v1, c, im, inn, dt)
    zeta = _attitude_rotation(v0, v1, s, c, im, inn, dt)
    phi = axpy3(1.0 / 12.0, cross3(dth0, dth), dth)
    q1 = qnormalize(qmul(qmul(rotvec_to_quat((-zeta[0], -zeta[1], -zeta[2])), q0),
                         rotvec_to_quat(phi)))
    _store(row, lat1, lon1, h1, v1, q1, dth, dv, dt)


@njit(cache=True, inline="always")
def inverse_step(row, v1, q1, dt):
    """The error-free increments (Δθ rad, Δv m/s) that carry the row's state to the sampled
    velocity ``v1`` (NED m/s) and attitude ``q1`` (unit quaternion) over Δt (s) under
    :func:`forward_step`; the row is advanced to the sample (position by :func:`position_step`)."""
    dth0 = (row[DTH], row[DTH + 1], row[DTH + 2])
    dv0 = (row[DV], row[DV + 1], row[DV + 2])
    q0 = (row[QUAT], row[QUAT + 1], row[QUAT + 2], row[QUAT + 3])
    v0 = (row[VEL], row[VEL + 1], row[VEL + 2])
    _, vm, s, c, im, inn, g = step_point(row, dt)
    zeta_v, dv_gc = velocity_terms(vm, s, c, im, inn, g, dt)
    lat1, lon1, h1 = position_step(row[LAT], row[LON], row[H], v0, v1, c, im, inn, dt)
    zeta = _attitude_rotation(v0, v1, s, c, im, inn, dt)
    phi = quat_to_rotvec(qmul(qmul(qconj(q0), rotvec_to_quat(zeta)), q1))
    c12 = (dth0[0] / 12.0, dth0[1] / 12.0, dth0[2] / 12.0)
    dth = solve_i_plus_skew(c12, phi)
    dvn = (v1[0] - v0[0] - dv_gc[0], v1[1] - v0[1] - dv_gc[1], v1[2] - v0[2] - dv_gc[2])
    dvn = solve_i_plus_skew((-0.5 * zeta_v[0], -0.5 * zeta_v[1], -0.5 * zeta_v[2]), dvn)
    scul = axpy3(-1.0 / 12.0, cross3(dv0, dth), qrot(qconj(q0), dvn))
    dv = solve_i_plus_skew(axpy3(0.5, dth, c12), scul)
    _store(row, lat1, lon1, h1, v1, q1, dth, dv, dt)
    return dth, dv


def new_row(lat_rad: float, lon_rad: float, alt_m: float, v_ned_mps, q_bn) -> np.ndarray:
    """A state row at rest in history (no previous increments, no previous state).

    Parameters
    ----------
    lat_rad, lon_rad : geodetic latitude and longitude, rad
    alt_m : ellipsoidal height, m
    v_ned_mps : (3,) velocity over the Earth, NED, m/s
    q_bn : (4,) attitude quaternion q_b^n, scalar first
    """
    row = np.zeros(NS)
    row[LAT], row[LON], row[H] = lat_rad, lon_rad, alt_m
    row[VEL:VEL + 3] = v_ned_mps
    row[QUAT:QUAT + 4] = q_bn
    return row


__all__ = ["NS", "forward_step", "inverse_step", "position_step", "velocity_terms",
           "step_point", "new_row", "euler_to_quat", "quat_to_euler", "rotvec_to_quat",
           "quat_to_rotvec", "qmul", "qconj", "qrot", "qnormalize", "cross3"]
